#include "render/view_modes.h"

#include "base/error.h"
#include "base/number_list.h"
#include "multires/hierarchy.h"
#include "solver/diffusion_matrix.h"
#include "solver/material.h"
#include "tetops/cut.h"
#include "tetops/quality.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace waxwork {

namespace {

using Colour = std::array<float, 3>;

Colour lerp(const Colour& a, const Colour& b, double t) {
    const auto f = static_cast<float>(std::clamp(t, 0.0, 1.0));
    return {a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])};
}

// Piecewise-linear map through evenly spaced stops.
Colour sample_stops(const std::vector<Colour>& stops, double t) {
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * static_cast<double>(stops.size() - 1);
    const size_t i = std::min(static_cast<size_t>(t), stops.size() - 2);
    return lerp(stops[i], stops[i + 1], t - static_cast<double>(i));
}

// Inferno-like stops (linear rgb): black, purple, red-orange, yellow, pale yellow. Luminance rises
// monotonically, so "brighter" on the slice means "more light".
const std::vector<Colour>& fluence_stops() {
    static const std::vector<Colour> stops = {
        {0.0f, 0.0f, 0.004f}, {0.10f, 0.01f, 0.22f}, {0.55f, 0.05f, 0.10f}, {0.95f, 0.35f, 0.02f}, {0.98f, 0.90f, 0.45f}};
    return stops;
}

const Colour kRed = {0.85f, 0.05f, 0.03f}, kYellow = {0.95f, 0.80f, 0.05f}, kGreen = {0.10f, 0.65f, 0.15f};

// Distinct hues for hierarchy levels 1, 2, ... (level 0 gets no point).
const std::vector<Colour>& level_palette() {
    static const std::vector<Colour> palette = {{0.90f, 0.10f, 0.10f}, {0.95f, 0.60f, 0.05f}, {0.20f, 0.75f, 0.15f},
                                                {0.10f, 0.55f, 0.95f}, {0.60f, 0.20f, 0.90f}, {0.95f, 0.30f, 0.75f},
                                                {0.10f, 0.85f, 0.80f}, {0.95f, 0.95f, 0.95f}};
    return palette;
}

}  // namespace

const std::vector<ViewMode>& all_view_modes() {
    static const std::vector<ViewMode> modes = {ViewMode::Radiance,  ViewMode::Materials, ViewMode::Quality,
                                                ViewMode::Wireframe, ViewMode::Slice,     ViewMode::Levels};
    return modes;
}

const char* view_mode_name(ViewMode mode) {
    switch (mode) {
        case ViewMode::Radiance: return "radiance";
        case ViewMode::Materials: return "materials";
        case ViewMode::Quality: return "quality";
        case ViewMode::Wireframe: return "wireframe";
        case ViewMode::Slice: return "slice";
        case ViewMode::Levels: return "levels";
    }
    return "radiance";
}

ViewMode parse_view_mode(std::string_view name) {
    std::string names;
    for (ViewMode mode : all_view_modes()) {
        if (name == view_mode_name(mode)) return mode;
        names += (names.empty() ? "" : ", ") + std::string(view_mode_name(mode));
    }
    throw InvalidArgumentError("unknown view '" + std::string(name) + "' (" + names + ")");
}

void validate(const ViewOptions& options) {
    if (!options.slice_normal.allFinite() || options.slice_normal.norm() == 0)
        throw InvalidArgumentError("the slice normal must be finite and non-zero");
    if (!std::isfinite(options.slice_offset) || std::abs(options.slice_offset) > 1)
        throw InvalidArgumentError("the slice offset must be in [-1, 1] (a fraction of the half extent along the normal)");
}

Eigen::Vector3d parse_slice_normal(std::string_view text) {
    const auto fail = [&](const std::string& why) {
        throw InvalidArgumentError("bad slice normal '" + std::string(text) + "': " + why);
    };
    std::vector<double> v;
    if (!parse_number_list(text, v) || v.size() != 3) fail("expected three numbers X,Y,Z");
    const Eigen::Vector3d normal(v[0], v[1], v[2]);
    if (!normal.allFinite() || normal.norm() == 0) fail("the normal must be finite and non-zero");
    return normal;
}

std::array<float, 3> quality_colour(double angle) {
    if (!(angle > kQualityRedDeg)) return kRed;  // also NaN (a degenerate tet)
    if (angle < kQualityYellowDeg) return lerp(kRed, kYellow, (angle - kQualityRedDeg) / (kQualityYellowDeg - kQualityRedDeg));
    return lerp(kYellow, kGreen, (angle - kQualityYellowDeg) / (kQualityGreenDeg - kQualityYellowDeg));
}

std::array<float, 3> fluence_colour(double t) { return sample_stops(fluence_stops(), t); }

std::array<float, 3> material_colour(const TetMaterial& material) {
    // The colour a thick slab of the material shows under white light, per channel: it separates
    // materials whose albedos all lie close to 1 far better than the albedo does.
    const std::array<double, 3> reflectance = diffuse_reflectance(material);
    const double peak = std::max({reflectance[0], reflectance[1], reflectance[2]});
    Colour colour{};
    for (int c = 0; c < 3; ++c) colour[c] = peak > 0 ? static_cast<float>(0.9 * reflectance[c] / peak) : 0.5f;
    return colour;
}

ViewGeometry materials_view(const BoundarySurface& surface, const std::vector<TetMaterial>& materials) {
    ViewGeometry view;
    view.mode = ViewMode::Materials;
    view.shading = SurfaceShading::TriangleColour;
    view.legend.title = "material (colour of its diffuse reflectance)";
    view.colours.resize(surface.triangles.size());
    // Painted volumes hold few distinct materials in long runs: compute each run's colour once.
    const TetMaterial* last = nullptr;
    Colour colour{};
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
        const auto tet = static_cast<size_t>(surface.triangle_tets[t]);
        if (tet >= materials.size()) throw InvalidArgumentError("materials view: no material for tet " + std::to_string(tet));
        if (!last || !(*last == materials[tet])) {
            last = &materials[tet];
            colour = material_colour(*last);
            const std::string label = material_label(*last);
            const bool listed = std::any_of(view.legend.swatches.begin(), view.legend.swatches.end(),
                                            [&](const auto& s) { return s.second == colour; });
            if (!listed && view.legend.swatches.size() < 12) view.legend.swatches.emplace_back(label, colour);
        }
        view.colours[t] = colour;
    }
    return view;
}

ViewGeometry quality_view(const TetMesh& mesh, const BoundarySurface& surface) {
    ViewGeometry view;
    view.mode = ViewMode::Quality;
    view.shading = SurfaceShading::TriangleColour;
    view.legend.title = "minimum dihedral angle of the face's tet";
    view.legend.units = "degrees";
    view.legend.low = 0;
    view.legend.high = kQualityGreenDeg;
    for (int i = 0; i <= 8; ++i) view.legend.stops.push_back(quality_colour(kQualityGreenDeg * i / 8.0));
    // Dihedral angles do not change under a piece's rigid motion: rest positions suffice.
    view.colours.resize(surface.triangles.size());
    tbb::parallel_for(size_t{0}, surface.triangles.size(), [&](size_t t) {
        const Tet& tet = mesh.tets[static_cast<size_t>(surface.triangle_tets[t])];
        view.colours[t] = quality_colour(min_dihedral_angle_deg(mesh.positions[tet[0]], mesh.positions[tet[1]],
                                                                mesh.positions[tet[2]], mesh.positions[tet[3]]));
    });
    return view;
}

ViewGeometry wireframe_view(const TetMesh& mesh, const TetConnectivity& connectivity) {
    ViewGeometry view;
    view.mode = ViewMode::Wireframe;
    view.legend.title = "tet edges (hidden behind the surface)";
    view.legend.swatches.emplace_back(std::to_string(connectivity.edges.size()) + " edges", Colour{0.02f, 0.02f, 0.03f});
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    RenderOverlay& o = view.overlay;
    o.line_vertices.resize(2 * connectivity.edges.size());
    o.line_colours.assign(o.line_vertices.size(), view.legend.swatches.front().second);
    tbb::parallel_for(size_t{0}, connectivity.edges.size(), [&](size_t e) {
        o.line_vertices[2 * e] = world[connectivity.edges[e][0]].cast<float>();
        o.line_vertices[2 * e + 1] = world[connectivity.edges[e][1]].cast<float>();
    });
    return view;
}

namespace {

// The slice plane of `options` for the volume's world-space box: n.p = c with n unit.
struct Plane {
    Eigen::Vector3d normal;
    double offset = 0;
};

Plane slice_plane(const std::vector<Eigen::Vector3d>& world, const ViewOptions& options) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& p : world) box.extend(p);
    Plane plane;
    plane.normal = options.slice_normal.normalized();
    // The box's half extent along n: the support function of the box minus its centre.
    const double half_extent = 0.5 * (box.max() - box.min()).cwiseAbs().dot(plane.normal.cwiseAbs());
    plane.offset = plane.normal.dot(box.center()) + options.slice_offset * half_extent;
    return plane;
}

// Keep n.p - c <= 0; the renderer keeps plane.xyz . p + plane.w >= 0.
Eigen::Vector4f clip_plane_of(const Plane& plane) {
    return Eigen::Vector4f(static_cast<float>(-plane.normal.x()), static_cast<float>(-plane.normal.y()),
                           static_cast<float>(-plane.normal.z()), static_cast<float>(plane.offset));
}

// The plane's intersection with the tets, as triangles: per corner its position, the weights of
// its two tet vertices (value = (1 - t) f(a) + t f(b)) and the tet it lies in. A crossed tet gives a
// triangle (one vertex on one side) or a quadrilateral (two on each side) split in two.
struct Section {
    std::vector<Eigen::Vector3f> points;
    std::vector<std::array<int32_t, 2>> ends;
    std::vector<double> t;
    std::vector<int32_t> tets;
};

Section cross_section(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& world, const Plane& plane) {
    Section section;
    const Eigen::Vector3d& n = plane.normal;
    const double c = plane.offset;
    for (size_t tet_index = 0; tet_index < mesh.tets.size(); ++tet_index) {
        const Tet& tet = mesh.tets[tet_index];
        std::array<double, 4> d;
        int below = 0;
        for (int k = 0; k < 4; ++k) {
            d[k] = n.dot(world[tet[k]]) - c;
            below += d[k] < 0;
        }
        if (below == 0 || below == 4) continue;
        std::vector<std::pair<int, int>> edges;  // crossed edges, in polygon order
        std::array<int, 4> lo{}, hi{};
        int nl = 0, nh = 0;
        for (int k = 0; k < 4; ++k) (d[k] < 0 ? lo[nl++] : hi[nh++]) = k;
        if (nl == 1 || nh == 1) {
            const int apex = nl == 1 ? lo[0] : hi[0];
            const std::array<int, 4>& others = nl == 1 ? hi : lo;
            edges = {{apex, others[0]}, {apex, others[1]}, {apex, others[2]}};
        } else {
            // Edges a-c, a-d, b-d, b-c: consecutive ones share a vertex, so they bound a convex
            // quadrilateral, split into (0, 1, 2) and (0, 2, 3).
            const std::array<std::pair<int, int>, 4> quad = {
                {{lo[0], hi[0]}, {lo[0], hi[1]}, {lo[1], hi[1]}, {lo[1], hi[0]}}};
            edges = {quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]};
        }
        for (const auto& [a, b] : edges) {
            const double t = d[a] / (d[a] - d[b]);
            section.points.push_back((world[tet[a]] + t * (world[tet[b]] - world[tet[a]])).cast<float>());
            section.ends.push_back({tet[a], tet[b]});
            section.t.push_back(t);
            section.tets.push_back(static_cast<int32_t>(tet_index));
        }
    }
    return section;
}

}  // namespace

ViewGeometry slice_view(const TetMesh& mesh, const std::vector<std::array<double, 3>>& phi, const ViewOptions& options) {
    validate(options);
    if (phi.size() != mesh.vertex_count())
        throw InvalidArgumentError("slice view: " + std::to_string(phi.size()) + " fluence values for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    ViewGeometry view;
    view.mode = ViewMode::Slice;
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const Plane plane = slice_plane(world, options);
    view.clip_plane = clip_plane_of(plane);
    Section section = cross_section(mesh, world, plane);
    // phi interpolated linearly along the crossed edges, as the solve's piecewise-linear fluence is.
    std::vector<double> values(section.points.size());
    for (size_t i = 0; i < values.size(); ++i)
        values[i] = (1 - section.t[i]) * luminance(phi[section.ends[i][0]]) + section.t[i] * luminance(phi[section.ends[i][1]]);
    // Log scale over three decades below the brightest point of the slice.
    constexpr double kDecades = 3;
    double peak = 0;
    for (double v : values)
        if (std::isfinite(v)) peak = std::max(peak, v);
    const double low = peak > 0 ? peak * std::pow(10.0, -kDecades) : 0;
    view.overlay.triangle_vertices = std::move(section.points);
    view.overlay.triangle_colours.resize(values.size());
    for (size_t i = 0; i < values.size(); ++i) {
        const double t = low > 0 && values[i] > 0 ? std::log10(values[i] / low) / kDecades : 0.0;
        view.overlay.triangle_colours[i] = fluence_colour(t);
    }
    view.legend.title = "fluence phi on the slice (luminance)";
    view.legend.units = "relative to the slice's brightest point, log scale";
    view.legend.logarithmic = true;
    view.legend.low = peak > 0 ? std::pow(10.0, -kDecades) : 0;
    view.legend.high = 1;
    for (int i = 0; i <= 8; ++i) view.legend.stops.push_back(fluence_colour(i / 8.0));
    return view;
}

ViewGeometry interior_quality_view(const TetMesh& mesh, const BoundarySurface& surface, const ViewOptions& options) {
    validate(options);
    ViewGeometry view = quality_view(mesh, surface);
    view.legend.title = "minimum dihedral angle of the tet (surface and slice)";
    const std::vector<Eigen::Vector3d> world = world_positions(mesh);
    const Plane plane = slice_plane(world, options);
    view.clip_plane = clip_plane_of(plane);
    Section section = cross_section(mesh, world, plane);
    // One colour per crossed tet, flat over its polygon.
    std::vector<Colour> tet_colour(mesh.tet_count());
    std::vector<uint8_t> done(mesh.tet_count(), 0);
    view.overlay.triangle_colours.resize(section.points.size());
    for (size_t i = 0; i < section.points.size(); ++i) {
        const auto t = static_cast<size_t>(section.tets[i]);
        if (!done[t]) {
            const Tet& tet = mesh.tets[t];
            tet_colour[t] = quality_colour(min_dihedral_angle_deg(mesh.positions[tet[0]], mesh.positions[tet[1]],
                                                                  mesh.positions[tet[2]], mesh.positions[tet[3]]));
            done[t] = 1;
        }
        view.overlay.triangle_colours[i] = tet_colour[t];
    }
    view.overlay.triangle_vertices = std::move(section.points);
    return view;
}

std::vector<int32_t> hierarchy_vertex_levels(const TetMesh& mesh, const TetConnectivity& connectivity) {
    HierarchyOptions options;
    // The solver stops coarsening at 1000 vertices; the view goes further so small volumes show levels.
    options.min_coarse_vertices = 32;
    std::vector<int32_t> level(mesh.vertex_count(), 0);
    const std::vector<std::vector<int32_t>> levels = hierarchy_level_vertices(connectivity.vertex_vertices, options);
    for (size_t l = 0; l < levels.size(); ++l)
        for (const int32_t v : levels[l]) level[static_cast<size_t>(v)] = static_cast<int32_t>(l + 1);
    return level;
}

ViewGeometry levels_view(const BoundarySurface& surface, const std::vector<int32_t>& vertex_levels) {
    ViewGeometry view;
    view.mode = ViewMode::Levels;
    view.shading = SurfaceShading::VertexColour;
    view.colours.assign(surface.positions.size(), Colour{0.45f, 0.45f, 0.48f});
    view.legend.title = "coarsest hierarchy level keeping the vertex (grey surface: level 0 only)";
    const std::vector<Colour>& palette = level_palette();
    int32_t deepest = 0;
    std::vector<size_t> counts;
    for (size_t s = 0; s < surface.vertices.size(); ++s) {
        const auto v = static_cast<size_t>(surface.vertices[s]);
        if (v >= vertex_levels.size()) throw InvalidArgumentError("levels view: no level for vertex " + std::to_string(v));
        const int32_t level = vertex_levels[v];
        if (level <= 0) continue;
        deepest = std::max(deepest, level);
        if (counts.size() <= static_cast<size_t>(level)) counts.resize(static_cast<size_t>(level) + 1, 0);
        ++counts[static_cast<size_t>(level)];
        view.overlay.points.push_back(surface.positions[s].cast<float>());
        view.overlay.point_colours.push_back(palette[static_cast<size_t>(level - 1) % palette.size()]);
    }
    view.overlay.point_size = 5.0f;
    for (int32_t l = 1; l <= deepest; ++l)
        view.legend.swatches.emplace_back("level " + std::to_string(l) + ": " + std::to_string(counts[l]) + " boundary vertices",
                                          palette[static_cast<size_t>(l - 1) % palette.size()]);
    return view;
}

ViewGeometry on_shading_vertices(ViewGeometry view, const ShadingSurface& shading) {
    if (view.shading != SurfaceShading::VertexColour) return view;
    std::vector<std::array<float, 3>> colours(shading.size());
    for (size_t d = 0; d < shading.size(); ++d) {
        const auto s = static_cast<size_t>(shading.surface_vertex[d]);
        if (s >= view.colours.size()) throw InvalidArgumentError("on_shading_vertices: the view was built for another surface");
        colours[d] = view.colours[s];
    }
    view.colours = std::move(colours);
    return view;
}

ViewGeometry build_view_geometry(const TetMesh& mesh, const TetConnectivity& connectivity,
                                 const std::vector<TetMaterial>& materials, const SolvedScene& scene,
                                 const ViewOptions& options) {
    validate(options);
    const auto on_surface = [&]() -> ViewGeometry {
        switch (options.mode) {
            case ViewMode::Radiance: return ViewGeometry{};
            case ViewMode::Materials: return materials_view(scene.surface, materials);
            case ViewMode::Quality:
                return options.quality_interior ? interior_quality_view(mesh, scene.surface, options)
                                                : quality_view(mesh, scene.surface);
            case ViewMode::Wireframe: return wireframe_view(mesh, connectivity);
            case ViewMode::Slice: return slice_view(mesh, scene.diffusion.phi, options);
            case ViewMode::Levels: return levels_view(scene.surface, hierarchy_vertex_levels(mesh, connectivity));
        }
        return ViewGeometry{};
    };
    return on_shading_vertices(on_surface(), scene.shading);
}

void apply_view(const ViewGeometry& view, SurfaceRenderInput& input) {
    if (view.shading == SurfaceShading::VertexColour && view.colours.size() != input.positions.size())
        throw InvalidArgumentError("apply_view: the view was built for another surface");
    if (view.shading == SurfaceShading::TriangleColour && view.colours.size() != input.triangles.size())
        throw InvalidArgumentError("apply_view: the view was built for another surface");
    input.shading = view.shading;
    input.colours = view.colours;
    input.overlay = view.overlay;
    input.clip_plane = view.clip_plane;
}

std::shared_ptr<const ViewGeometry> ViewGeometryCache::get(const TetMesh& mesh, const TetConnectivity& connectivity,
                                                           const std::vector<TetMaterial>& materials,
                                                           const SolvedScene& scene, const ViewOptions& options,
                                                           long long geometry_version, long long solution_version) {
    const bool same_options = options_ && options_->mode == options.mode &&
                              options_->slice_normal == options.slice_normal &&
                              options_->slice_offset == options.slice_offset &&
                              options_->quality_interior == options.quality_interior;
    const bool stale = !view_ || !same_options || geometry_version != geometry_version_ ||
                       (options.mode == ViewMode::Slice && solution_version != solution_version_);
    if (!stale) return view_;
    if (options.mode == ViewMode::Levels) {
        if (levels_version_ != geometry_version) {
            levels_ = hierarchy_vertex_levels(mesh, connectivity);
            levels_version_ = geometry_version;
        }
        validate(options);
        view_ = std::make_shared<const ViewGeometry>(on_shading_vertices(levels_view(scene.surface, levels_), scene.shading));
    } else {
        view_ = std::make_shared<const ViewGeometry>(build_view_geometry(mesh, connectivity, materials, scene, options));
    }
    options_ = options;
    geometry_version_ = geometry_version;
    solution_version_ = solution_version;
    ++builds_;
    return view_;
}

}  // namespace waxwork
