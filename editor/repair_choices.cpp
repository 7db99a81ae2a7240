#include "editor/repair_choices.h"

namespace waxwork {

std::vector<RepairChoice> repair_choices(const SurfaceDefects& defects, bool wrapping_would_fix,
                                         const SurfaceRepairOptions& tried) {
    std::vector<RepairChoice> choices;
    const bool holes = defects.boundary_edges > 0;
    const bool intersections = defects.self_intersecting_pairs > 0;
    // repair_hard_defects refuses to start on anything else (and a wrap replaces them when asked for).
    const bool workable = defects.non_finite_points == 0 && defects.invalid_indices == 0 &&
                          defects.non_manifold_edges == 0 && defects.non_manifold_vertices == 0 &&
                          defects.inconsistent_edges == 0;
    // Hard repairs that ran and left the surface defective would only do the same again.
    const bool already_tried = tried.wrap || tried.fill_holes || tried.autorefine;
    if (workable && (holes || intersections) && !already_tried) {
        RepairChoice hard;
        hard.repair = tried;
        hard.repair.fill_holes = holes;
        hard.repair.autorefine = intersections;
        hard.id = holes && intersections ? "fill_holes_autorefine" : holes ? "fill_holes" : "autorefine";
        hard.label = holes && intersections ? "Fill holes and remove self-intersections"
                     : holes               ? "Fill holes"
                                           : "Remove self-intersections";
        choices.push_back(std::move(hard));
    }
    if (wrapping_would_fix && !tried.wrap) {
        RepairChoice wrap;
        wrap.id = "wrap";
        wrap.label = "Repair by wrapping";
        wrap.repair = tried;
        // The wrap replaces the other repairs (the session format refuses both at once).
        wrap.repair.fill_holes = false;
        wrap.repair.autorefine = false;
        wrap.repair.wrap = WrapOptions{};
        choices.push_back(std::move(wrap));
    }
    return choices;
}

}  // namespace waxwork
