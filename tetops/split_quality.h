// The quality guarantee of exact splitting (exact_cut.h and fracture.h): no tet that a split
// creates or moves may end with a minimum dihedral angle under min(guard, that of the tet it came
// from before the operation). Snapping checks the guard before moving a vertex (exact_cut.cpp); the
// case split of a crossed tet cannot choose its shapes, so afterwards a guarded optimisation moves
// the vertices around poor new tets (vertices on the cutting surface or on walls between regions
// only within them, boundary vertices only within flat parts and along straight creases of the
// outer surface), and whatever is still under the guard is counted, never hidden.
#pragma once

#include "tetops/tet_mesh.h"

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace waxwork {

class SplitField;

// A face at a vertex that must keep its plane: on the boundary of the volume (met once in the vertex's
// star) or between two regions (met twice, by tets of different labels).
struct KeptFace {
    std::array<int32_t, 3> vertices;
    bool on_boundary;
};

// The kept faces of v's star that contain v. Every tet sharing a face through v also contains v, so
// counting faces within the star is enough. `labels` (per tet, may be null) tells the regions apart.
std::vector<KeptFace> kept_faces_at(const TetMesh& mesh, const std::vector<int32_t>& star, int32_t v,
                                    const std::vector<int64_t>* labels);

// The value the guard compares a tet with: min(guard, its reference angle). A NaN reference marks a
// tet nobody has touched yet, which is never under the guard.
inline double guard_floor_deg(double guard_deg, double reference_deg) {
    return reference_deg < guard_deg ? reference_deg : guard_deg;
}

// Tets whose minimum dihedral angle is under min(guard, reference[t]); tets with a NaN reference
// (untouched) are skipped, and with `only` (per tet) those not flagged. Counted from the mesh as it
// is (parallel).
size_t count_tets_under_guard(const TetMesh& mesh, const std::vector<double>& reference_deg, double guard_deg,
                              const std::vector<uint8_t>* only = nullptr);

struct SplitSmoothingOptions {
    double guard_deg = 0.5;
    // Vertices are optimised while the worst tet of their star is under this angle (degrees): above it
    // the split region is left as the case table made it.
    double target_deg = 5;
    int max_sweeps = 4;
};

// Guarded optimisation of the vertices of the tets flagged in `start` (per tet of `mesh`) whose minimum
// dihedral angle is under the target. Each move maximises the worst angle of the vertex's star and is
// accepted only if it improves it and every tet of the star stays at or above min(guard, its
// reference) or does not get worse. A vertex whose `values` entry is 0 stays on the surface of
// `field` (re-projected when the field can project, else held in the plane of its faces on the
// surface); faces on the boundary or between different `labels` keep their planes, so a vertex moves
// only in the space their normals leave free (none: it stays). `reference_deg` (per tet, NaN =
// untouched) is filled in, and `touched` (per tet) set, for every tet of the star of a moved vertex.
// `world` is kept in step with positions (rest frames of the pieces). Deterministic: vertices are
// coloured so that no two of one colour share a tet and each colour moves in parallel; a vertex is
// revisited only when it or a neighbour moved in the previous sweep. Returns the vertices moved.
size_t smooth_split_vertices(TetMesh& mesh, std::vector<Eigen::Vector3d>& world, const std::vector<double>& values,
                             const SplitField& field, const std::vector<int64_t>& labels,
                             std::vector<double>& reference_deg, const std::vector<uint8_t>& start,
                             std::vector<uint8_t>& touched, const SplitSmoothingOptions& options = {});

}  // namespace waxwork
