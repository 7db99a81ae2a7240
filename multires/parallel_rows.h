// Row loops of the multigrid code: each row is independent, so TBB splits the range into chunks of
// `grain` rows (large enough that scheduling costs less than the rows themselves).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace waxwork {

template <typename Body>
void for_rows(size_t n, size_t grain, const Body& body) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
}

}  // namespace waxwork
