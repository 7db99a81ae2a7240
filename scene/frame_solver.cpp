#include "scene/frame_solver.h"

#include <algorithm>
#include <limits>

namespace waxwork {

FrameBudget budget_until(const FrameDeadline& deadline, int parts, int max_iterations) {
    const double share = deadline.remaining() / std::max(parts, 1);
    return FrameBudget::milliseconds(std::max(share, std::numeric_limits<double>::denorm_min()), max_iterations);
}

}  // namespace waxwork
