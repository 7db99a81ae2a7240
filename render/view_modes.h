// The editor's optional views: besides the physical image (radiance), views that show what
// the solve works on. Each is built from the mesh and the solved scene by a free function into a
// ViewGeometry (colours for the surface, overlay geometry, a clip plane, a legend) that apply_view()
// puts into the renderer's input; the renderer itself only knows generic colours, overlays and a clip
// plane (render/surface_renderer.h). `waxwork render --show MODE` and the editor's View panel use the
// same functions, so both draw the same picture.
//
//   radiance    the physical image: F_t E plus shadowed Cook-Torrance highlights, tone-mapped
//   materials   each surface triangle in the colour of its tet's material (its single-scattering
//               albedo mu_s' / (mu_s' + mu_a) per channel, brightened to a hue)
//   quality     each surface triangle coloured by its tet's minimum dihedral angle (red: sliver);
//               optionally also the slice plane's cross-section of the interior tets
//   wireframe   the radiance image with every tet edge drawn over it (edges behind the surface hidden)
//   slice       a plane through the volume: the plane's intersection with the tets coloured by the
//               interpolated fluence phi (log scale), the surface on the normal's side cut away
//   levels      the multi-resolution hierarchy (multires/hierarchy.h, TransCut Sec. 4.1): each
//               boundary vertex as a point coloured by the coarsest level that keeps it
#pragma once

#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace waxwork {

enum class ViewMode { Radiance, Materials, Quality, Wireframe, Slice, Levels };

// All modes in menu order.
const std::vector<ViewMode>& all_view_modes();
// "radiance", "materials", "quality", "wireframe", "slice", "levels".
const char* view_mode_name(ViewMode mode);
// Throws InvalidArgumentError("unknown view 'X' (radiance, materials, ...)").
ViewMode parse_view_mode(std::string_view name);

struct ViewOptions {
    ViewMode mode = ViewMode::Radiance;
    // Slice: the plane's unit normal points at the half that is cut away; the plane passes through
    // the bounding box's centre moved by slice_offset times the box's half extent along the normal
    // (so -1 and 1 touch the box, 0 halves it).
    Eigen::Vector3d slice_normal = Eigen::Vector3d(0, 0, 1);
    double slice_offset = 0;
    // Quality: also cut the volume with the slice plane and colour the cross-section by the quality
    // of the tets it crosses (slivers inside the volume, not only at its surface).
    bool quality_interior = false;
};

// Throws InvalidArgumentError for a zero or non-finite normal or an offset outside [-1, 1].
void validate(const ViewOptions& options);
// Parses "X,Y,Z" for --slice-normal; throws InvalidArgumentError("bad slice normal 'TEXT': WHY").
Eigen::Vector3d parse_slice_normal(std::string_view text);

// What the legend shows: a colour scale from `low` to `high` in `units` (`stops` evenly spaced), or
// named swatches (materials, levels).
struct ViewLegend {
    std::string title;
    std::string units;
    std::vector<std::array<float, 3>> stops;  // linear rgb, low to high
    double low = 0, high = 0;
    bool logarithmic = false;
    std::vector<std::pair<std::string, std::array<float, 3>>> swatches;
};

struct ViewGeometry {
    ViewMode mode = ViewMode::Radiance;
    SurfaceShading shading = SurfaceShading::Radiance;
    std::vector<std::array<float, 3>> colours;  // per surface vertex or triangle, as `shading` says
    RenderOverlay overlay;
    std::optional<Eigen::Vector4f> clip_plane;
    ViewLegend legend;
};

// The colour maps (linear rgb). quality_colour: red at or below 5 degrees, yellow at 20, green from 40
// (TetGen's default quality bound keeps dihedral angles above about 10 degrees; slivers fall far below).
// fluence_colour: t in [0, 1] along an inferno-like map whose luminance rises monotonically.
inline constexpr double kQualityRedDeg = 5, kQualityYellowDeg = 20, kQualityGreenDeg = 40;
std::array<float, 3> quality_colour(double min_dihedral_deg);
std::array<float, 3> fluence_colour(double t);
// A material's display colour: its diffuse reflectance per channel (solver/material.h) scaled so the
// largest channel is 0.9.
std::array<float, 3> material_colour(const TetMaterial& material);

// The individual views. `surface` is the scene's boundary (SolvedScene::surface): vertex colours are
// per surface vertex, triangle colours line up with make_render_input's triangles (on_shading_vertices
// puts vertex colours on its vertices).
ViewGeometry materials_view(const BoundarySurface& surface, const std::vector<TetMaterial>& materials);
ViewGeometry quality_view(const TetMesh& mesh, const BoundarySurface& surface);
// quality_view plus the slice plane's cross-section coloured per tet, the surface clipped as for the
// slice view.
ViewGeometry interior_quality_view(const TetMesh& mesh, const BoundarySurface& surface, const ViewOptions& options);
ViewGeometry wireframe_view(const TetMesh& mesh, const TetConnectivity& connectivity);
// phi: per volume vertex (SolvedScene::diffusion.phi).
ViewGeometry slice_view(const TetMesh& mesh, const std::vector<std::array<double, 3>>& phi, const ViewOptions& options);
// Levels of each volume vertex: the index of the coarsest hierarchy level it belongs to (0: only the
// fine level). The solver's vertex selection on the mesh graph (hierarchy_level_vertices: the levels
// depend on the connectivity only, not on materials or operators), with a small coarsest size so that
// even a small volume shows several levels. It is the selection a fresh build makes: the live
// multires solver rebuilds its hierarchy around each cut (rebuild_multires_hierarchy), so near the
// cuts its selection may differ.
std::vector<int32_t> hierarchy_vertex_levels(const TetMesh& mesh, const TetConnectivity& connectivity);
ViewGeometry levels_view(const BoundarySurface& surface, const std::vector<int32_t>& vertex_levels);

// A view of vertex colours per surface vertex with its colours copied to the shading vertices
// (scene.shading: make_render_input's vertices); other views as they are. Throws InvalidArgumentError
// when the view was built for another surface.
ViewGeometry on_shading_vertices(ViewGeometry view, const ShadingSurface& shading);

// The view `options.mode` asks for, on make_render_input's vertices; Radiance gives an empty geometry. materials: one per tet (as
// solved). Throws InvalidArgumentError for bad options.
ViewGeometry build_view_geometry(const TetMesh& mesh, const TetConnectivity& connectivity,
                                 const std::vector<TetMaterial>& materials, const SolvedScene& scene,
                                 const ViewOptions& options);

// Puts the view into a render input made by make_render_input for the same scene.
void apply_view(const ViewGeometry& view, SurfaceRenderInput& input);

// Keeps the last view geometry (and the levels, which cost a hierarchy build) between frames: the
// editor's worker asks for the view every tick and only pays when the geometry, the options or (for
// the slice) the solution changed. Not synchronised: one worker uses it at a time.
class ViewGeometryCache {
public:
    // geometry_version: bumped by the caller whenever the mesh or its materials changed;
    // solution_version: whenever phi changed.
    std::shared_ptr<const ViewGeometry> get(const TetMesh& mesh, const TetConnectivity& connectivity,
                                            const std::vector<TetMaterial>& materials, const SolvedScene& scene,
                                            const ViewOptions& options, long long geometry_version,
                                            long long solution_version);
    int builds() const { return builds_; }

private:
    std::shared_ptr<const ViewGeometry> view_;
    std::optional<ViewOptions> options_;
    long long geometry_version_ = -1, solution_version_ = -1;
    std::vector<int32_t> levels_;
    long long levels_version_ = -1;
    int builds_ = 0;
};

}  // namespace waxwork
