// The repairs the editor offers when a surface is refused (io/surface_reader.h SurfaceRefusedError):
// one button per way out, each reopening the file with the command line's repair options set
// (--repair wrap, --fill-holes, --autorefine), so the editor opens what `waxwork mesh` would.
#pragma once

#include "tetops/surface_check.h"

#include <string>
#include <vector>

namespace waxwork {

struct RepairChoice {
    std::string id;     // what an input script names: "wrap", "fill_holes", "autorefine", "fill_holes_autorefine"
    std::string label;  // the button's text
    SurfaceRepairOptions repair;  // the options to reopen with
};

// The repairs that apply to a surface refused with `defects` after loading with `tried`: the hard
// repairs (filling holes, removing self-intersections: both when both defects are there) when the
// surface is otherwise one they can work on (edge- and vertex-manifold, consistently oriented, finite;
// surface_check.h repair_hard_defects) and no hard repair was tried already, then wrapping when
// `wrapping_would_fix` (it covers every defect but missing geometry). Each keeps `tried`'s other
// settings (max_triangles, the wrap's alpha and offset). Empty: nothing to offer.
std::vector<RepairChoice> repair_choices(const SurfaceDefects& defects, bool wrapping_would_fix,
                                         const SurfaceRepairOptions& tried);

}  // namespace waxwork
