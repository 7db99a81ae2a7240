// The boundary surface as the image shades it: every vertex where the surface folds by more than a
// crease angle (a cube's edges, a cut's rim, the walls of a fracture) is split into one copy per
// smooth fan of its triangles, each copy with the normal of its own fan.
//
// Why. BoundarySurface keeps one area-weighted normal per vertex. At a crease it leans halfway between
// the two sides, 45 degrees off each face of a cube, and everything evaluated with it reads the edge
// as though it were round: the light q a vertex receives (lighting.h) is the same for the lit face and
// the face in shade, and the exitant radiance E (Li et al. 2013, Eq. 3) subtracts q, so the face in
// shade shows a strip darkened by its lit neighbour's q, one triangle wide and jagged where the
// triangles are; the highlight and the Fresnel factor smear across the edge the same way. With the
// copies, q, the shadow visibility, E and the highlight are evaluated per fan (shading_light below,
// radiance.h: shading_radiance_factors), so each face shades as itself up to its edge.
//
// The diffusion solve integrates the same light fan by fan (source_light below): its right-hand side
// weighs q_i by the boundary area S_i of vertex i (Eq. 12), and at a crease that area lies on both
// sides, so q evaluated once with the averaged normal over-lights the rim of a lit face and lights
// the rim of a face turned away (on a cube lit head-on, an edge vertex received q at 45 degrees over
// its whole area instead of q at 0 degrees on the lit side and nothing on the grazed one).
#pragma once

#include "solver/diffusion_matrix.h"
#include "solver/environment_transfer.h"
#include "solver/lighting.h"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace waxwork {

// Triangles meeting at a vertex along a shared edge stay in one fan when their normals differ by at
// most this angle. Box edges turn by 90 degrees and cut rims mostly by far more than 40, while smooth
// models fold by less: spot meshed at 49,405 tets splits 140 of its 9,581 surface vertices (1.5%, at
// horn, ear and udder tips, where its own 5,856 triangles turn by up to 77 degrees), and 2,003 at 20
// degrees (ShadingSurface.SmoothModelsSplitAlmostNothingAtTheDefaultAngle prints the counts).
inline constexpr double kDefaultCreaseAngleDegrees = 40.0;

// Whether `degrees` is a crease angle split_at_creases takes: in [0, 180] (NaN is not). Every option,
// session field and script event that sets the angle checks it with this.
inline bool is_crease_angle(double degrees) { return degrees >= 0.0 && degrees <= 180.0; }

struct ShadingSurface {
    // The surface vertex each shading vertex copies. Shading vertex s < the surface's vertex count
    // copies surface vertex s (the fan of its first triangle); the further copies of split vertices
    // follow, by surface vertex, then fan.
    std::vector<int32_t> surface_vertex;
    // Unit, area-weighted over the copy's fan. A vertex that is not split keeps the surface's normal bit
    // for bit, so on a surface without creases every shaded value equals the unsplit one.
    std::vector<Eigen::Vector3d> normals;
    // The surface's triangles in its order, their corners renumbered into shading vertices.
    std::vector<std::array<int32_t, 3>> triangles;
    // Every copy of every split surface vertex, ascending: where the shading differs from the surface.
    std::vector<int32_t> split_copies;

    size_t size() const { return surface_vertex.size(); }
};

// Splits `surface` at its creases. crease_angle_degrees in [0, 180]: 180 splits nothing (the surface's
// own numbering, normals and triangles), 0 splits wherever neighbouring triangles are not coplanar
// (faceted shading; coplanar within rounding, 1e-9 in the cosine, stays one fan). Triangles of zero area join whichever fan they touch (they have no normal).
// Below 180, fans of a vertex that touch only at the vertex (two cones tip to tip) are copies too.
// Throws InvalidArgumentError for an angle outside [0, 180] or NaN, and for triangles indexing outside
// the surface.
ShadingSurface split_at_creases(const BoundarySurface& surface,
                                double crease_angle_degrees = kDefaultCreaseAngleDegrees);

// The light each shading vertex receives. Copies of vertices that are not split take the surface's q
// and visibility (incident_light's output for `surface`) as they are; the copies of split vertices
// get q and visibility evaluated with their own normal, from their surface vertex's position and eta
// (new shadow rays against `bvh`, built from `surface`).
struct ShadingLight {
    std::vector<Rgb> q;             // per shading vertex
    std::vector<float> visibility;  // per shading vertex and light, vertex-major (empty when the input's is)
};
// With an environment, the copies' q_env comes from `copy_transfer` (split_copy_transfer's) when
// given, else from one computed here.
ShadingLight shading_light(const BoundarySurface& surface, const ShadingSurface& shading, const TriangleBvh& bvh,
                           const Lighting& lighting, const std::vector<Rgb>& surface_q,
                           const std::vector<float>& surface_visibility,
                           const EnvironmentTransfer* copy_transfer = nullptr);

// Samples again the transfer of the split copies `copies` (indices into shading.split_copies) with
// `samples` rays, or with the transfer's own count when 0 (fewer rays stand in until a later call
// samples them fully, as the live scene does after an edit). InvalidArgumentError for an index out of
// range or a transfer of another size.
void update_split_copy_transfer(const BoundarySurface& surface, const ShadingSurface& shading, const TriangleBvh& bvh,
                                std::span<const int32_t> copies, EnvironmentTransfer& transfer, int samples = 0);

// The environment's transfer (environment_transfer.h) of each split copy with its own normal, in the
// order of shading.split_copies; `settings` as the surface's transfer.
EnvironmentTransfer split_copy_transfer(const BoundarySurface& surface, const ShadingSurface& shading,
                                        const TriangleBvh& bvh, const TransferSettings& settings);

// The light the diffusion solve takes per surface vertex: q_i of Eq. 12, whose source S_i q_i stands
// for the integral of q over the vertex's boundary area (the lumped S_f / 3 of each of its triangles).
// At a split vertex it is the mean of its copies' q weighted by their fans' areas, sum_c S_c q_c / S_i,
// so each side of a crease contributes the light it receives; a vertex that is not split keeps its q
// bit for bit, so on a surface without creases this is incident_light's q. The weights are areas only:
// where the triangles around a split vertex belong to tets of different refractive index (a painted
// border along a crease), Eq. 12 also weighs each face by its own 1/(A (1 - F_dr)), which this mean
// does not. Exact for the lumped source; the FEM variant's consistent boundary mass also carries a
// vertex's q into its neighbours' rows, where a per-face-corner source would be needed
// (tests/solver/crease_source_accuracy_test.cpp measures both). `shading_q` is per shading vertex
// (ShadingLight::q); throws InvalidArgumentError on mismatched sizes.
std::vector<Rgb> source_light(const BoundarySurface& surface, const ShadingSurface& shading,
                              const std::vector<Rgb>& shading_q);

// The rest of the light at creases: the face corners whose shading copy's q differs from the vertex's
// `q` (per surface vertex: source_light's), each with that difference (diffusion_matrix.h:
// add_corner_light). With them b integrates each face's own light exactly, for either discretisation
// and whatever the faces' refractive indices: source_light's mean is only exact for the lumped source
// of faces that share one eta. Only corners at split vertices are listed, ascending by face; faces are
// the surface's triangles, which are TetConnectivity::boundary_faces in order. Throws
// InvalidArgumentError on mismatched sizes.
std::vector<CornerLight> corner_light(const BoundarySurface& surface, const ShadingSurface& shading,
                                      const std::vector<Rgb>& shading_q, const std::vector<Rgb>& q);

}  // namespace waxwork
