// The editor's optional views (render/view_modes.h) and the shadowed highlights: what each view draws
// must say what it claims (hues where the materials are, red where a tet is bad, lines, a slice that
// is brighter towards the light with the cut-away half gone, several hierarchy levels), and a
// highlight must not shine where the surface is in shadow.
#include "base/error.h"
#include "gl/gl_context.h"
#include "render/render_input.h"
#include "render/surface_renderer.h"
#include "render/view_modes.h"
#include "scene/live_scene.h"
#include "solver/light_spec.h"
#include "solver/material.h"
#include "solver/solved_scene.h"
#include "support/cli_run.h"
#include "tetops/box_mesh.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/sliver_maker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace waxwork {
namespace {

using testing::run_waxwork;

// The boxes [lo0, hi0] and [lo1, hi1] as one volume (two components, one piece).
TetMesh two_boxes(const std::array<int, 3>& cells0, const Eigen::Vector3d& lo0, const Eigen::Vector3d& hi0,
                  const std::array<int, 3>& cells1, const Eigen::Vector3d& lo1, const Eigen::Vector3d& hi1) {
    return join_meshes(make_box_mesh(cells0, lo0, hi0), make_box_mesh(cells1, lo1, hi1));
}

DiffusionOptions quick_solve() {
    DiffusionOptions options;
    options.mm_per_unit = 10;
    options.relative_tolerance = 1e-3;
    return options;
}

// Pixel (column, row from the top) where world point p lands in an image framed like `input`.
Eigen::Vector2d project(const SurfaceRenderInput& input, const Eigen::Vector3d& p) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3f& q : input.positions) box.extend(q.cast<double>());
    const CameraFrame frame = frame_camera(box, input.camera, static_cast<double>(input.width) / input.height);
    const Eigen::Vector4d clip = frame.projection * frame.view * p.homogeneous();
    const Eigen::Vector2d ndc = clip.head<2>() / clip.w();
    return {(ndc.x() + 1) / 2 * input.width, (1 - ndc.y()) / 2 * input.height};
}

double luminance(const Image& image, int x, int y) {
    const uint8_t* p = image.pixel(x, y);
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

bool is_background(const Image& image, int x, int y, const SurfaceRenderInput& input) {
    const uint8_t* p = image.pixel(x, y);
    return std::abs(p[0] - input.background[0]) <= 2 && std::abs(p[1] - input.background[1]) <= 2 &&
           std::abs(p[2] - input.background[2]) <= 2;
}

size_t covered_pixels(const Image& image, const SurfaceRenderInput& input) {
    size_t count = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) count += !is_background(image, x, y, input);
    return count;
}

TEST(ViewModes, NamesRoundTripAndBadNamesAreRefused) {
    for (ViewMode mode : all_view_modes()) EXPECT_EQ(parse_view_mode(view_mode_name(mode)), mode);
    EXPECT_EQ(all_view_modes().size(), 6u);
    try {
        parse_view_mode("normals");
        FAIL() << "accepted an unknown view";
    } catch (const InvalidArgumentError& e) {
        EXPECT_NE(std::string(e.what()).find("'normals'"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("slice"), std::string::npos);  // lists the choices
    }
    EXPECT_EQ(parse_slice_normal("0,+1,-2"), Eigen::Vector3d(0, 1, -2));
    for (const char* bad : {"", "1,2", "1,2,3,4", "1,x,3", "0,0,0", "1,2,3 ", "nan,0,1"})
        EXPECT_THROW(parse_slice_normal(bad), InvalidArgumentError) << bad;
    ViewOptions options;
    options.slice_offset = 1.5;
    EXPECT_THROW(validate(options), InvalidArgumentError);
    options.slice_offset = 0.5;
    options.slice_normal = Eigen::Vector3d::Zero();
    EXPECT_THROW(validate(options), InvalidArgumentError);
}

// A slab under a floating cube, lit from above: the cube's shadow lies on the slab.
struct ShadowScene {
    TetMesh mesh = two_boxes({16, 1, 16}, {-2, 0, -2}, {2, 0.2, 2}, {3, 3, 3}, {-0.5, 1, -0.5}, {0.5, 2, 0.5});
    TetConnectivity connectivity = build_connectivity(mesh);
    std::vector<TetMaterial> materials = std::vector<TetMaterial>(mesh.tet_count(), material_preset("marble"));
    Lighting lighting;
    ShadowScene() {
        // Travelling down and towards +x: the shadow falls at x in about [-0.1, 1.4]; the camera sits
        // in the mirror direction, where the highlight is, and sees the shadow beside the cube.
        lighting.lights.push_back({LightType::Directional, Eigen::Vector3d(0.5, -1, 0), {1, 1, 1}});
        lighting.ambient = {0.02, 0.02, 0.02};
    }
};

TEST(ShadowedHighlights, VisibilityComesFromTheShadowRays) {
    const ShadowScene s;
    const SolvedScene scene = solve_scene(s.mesh, s.connectivity, s.materials, s.lighting, quick_solve());
    const std::vector<float>& visibility = scene.shading_light.visibility;
    ASSERT_EQ(visibility.size(), scene.shading.size());
    size_t shadowed = 0;
    for (size_t d = 0; d < scene.shading.size(); ++d) {
        const Eigen::Vector3d& p = scene.surface.positions[scene.shading.surface_vertex[d]];
        const bool top_of_slab = std::abs(p.y() - 0.2) < 1e-9;
        // Clearly inside or clearly outside the shadow of the cube on the slab's top.
        const bool under = top_of_slab && p.x() > 0.2 && p.x() < 1.2 && std::abs(p.z()) < 0.4;
        const bool free = top_of_slab && (std::abs(p.z()) > 0.7 || p.x() < -1.6);
        if (under) {
            EXPECT_EQ(visibility[d], 0.0f) << p.transpose();
        }
        if (free) {
            EXPECT_EQ(visibility[d], 1.0f) << p.transpose();
        }
        shadowed += visibility[d] == 0.0f;
    }
    EXPECT_GT(shadowed, 0u);
    // q agrees: the shadowed vertices get the ambient light alone, in the image and in the solve.
    for (size_t d = 0; d < scene.shading.size(); ++d)
        if (visibility[d] == 0.0f) {
            EXPECT_NEAR(scene.shading_light.q[d][0], 0.02, 1e-12);
            if (!std::binary_search(scene.shading.split_copies.begin(), scene.shading.split_copies.end(), d)) {
                EXPECT_NEAR(scene.q[scene.surface.vertices[scene.shading.surface_vertex[d]]][0], 0.02, 1e-12);
            }
        }
}

TEST(ShadowedHighlights, NoHighlightInTheShadowAndUnshadowedScenesUnchanged) {
    const ShadowScene s;
    const SolvedScene scene = solve_scene(s.mesh, s.connectivity, s.materials, s.lighting, quick_solve());
    ImageSettings settings;
    settings.width = 320;
    settings.height = 240;
    settings.camera.eye_direction = Eigen::Vector3d(0.5, 1, 0);  // the light's mirror direction
    settings.camera.up = Eigen::Vector3d(0, 0, -1);
    settings.exposure = 1.0f;
    SurfaceRenderInput input = make_render_input(s.mesh, scene, s.lighting, settings);
    ASSERT_FALSE(input.light_visibility.empty());
    input.roughness = 1.0f;         // a broad lobe: the highlight covers the whole slab
    input.specular_scale = 150.0f;  // and is strong enough to measure against the subsurface light
    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    const Image with_highlight = renderer.render(input);
    SurfaceRenderInput plain = input;
    plain.specular_scale = 0;
    const Image without = renderer.render(plain);
    SurfaceRenderInput unshadowed = input;
    unshadowed.light_visibility.clear();
    const Image old_behaviour = renderer.render(unshadowed);

    // The highlight's share of each pixel at the slab's top, in shadow and beside the shadow.
    auto highlight_at = [&](const Image& image, const Eigen::Vector3d& p) {
        const Eigen::Vector2d px = project(input, p);
        const int x = static_cast<int>(px.x()), y = static_cast<int>(px.y());
        return luminance(image, x, y) - luminance(without, x, y);
    };
    double in_shadow = 0, beside = 1e9, in_shadow_before = 1e9;
    for (double x : {0.4, 0.6, 0.8, 1.0}) {
        const Eigen::Vector3d shadowed(x, 0.2, 0.0), lit(x, 0.2, 1.2);
        in_shadow = std::max(in_shadow, highlight_at(with_highlight, shadowed));
        beside = std::min(beside, highlight_at(with_highlight, lit));
        in_shadow_before = std::min(in_shadow_before, highlight_at(old_behaviour, shadowed));
    }
    EXPECT_GT(beside, 20.0);                // a visible highlight where the light arrives
    EXPECT_GT(in_shadow_before, 20.0);      // which used to shine in the shadow as well
    EXPECT_LE(in_shadow, 2.0);              // and now does not

    // A convex volume shadows nothing: its visibility changes no pixel.
    const TetMesh box = make_box_mesh({4, 4, 4}, {-1, -1, -1}, {1, 1, 1});
    const TetConnectivity box_connectivity = build_connectivity(box);
    const std::vector<TetMaterial> marble(box.tet_count(), material_preset("marble"));
    const SolvedScene box_scene = solve_scene(box, box_connectivity, marble, s.lighting, quick_solve());
    SurfaceRenderInput box_input = make_render_input(box, box_scene, s.lighting, ImageSettings{160, 120, {}, 1.0f});
    box_input.specular_scale = 20;
    const Image shadowed_box = renderer.render(box_input);
    box_input.light_visibility.clear();
    EXPECT_EQ(renderer.render(box_input).rgba, shadowed_box.rgba);
}

TEST(ShadowedHighlights, LiveSceneCarriesTheVisibilityThroughRelighting) {
    ShadowScene s;
    s.mesh.materials = s.materials;
    LiveScene live(s.mesh, s.lighting);
    const auto expected = [&](const Lighting& lighting) {
        return solve_scene(s.mesh, s.connectivity, s.materials, lighting, quick_solve()).shading_light.visibility;
    };
    EXPECT_EQ(live.solved_scene().shading_light.visibility, expected(s.lighting));
    // A second light from straight above: the cube shadows the slab's centre for it as well.
    Lighting two = s.lighting;
    two.lights.push_back({LightType::Directional, Eigen::Vector3d(0, -1, 0), {1, 1, 1}});
    live.set_lighting(two);
    const std::vector<float> visibility = live.solved_scene().shading_light.visibility;
    EXPECT_EQ(visibility, expected(two));
    EXPECT_EQ(visibility.size(), 2 * live.solved_scene().shading.size());
    EXPECT_NE(std::count(visibility.begin(), visibility.end(), 0.0f), 0);
}

// A box of two materials: ketchup (red) for x < 0, apple (yellow-green) for x > 0.
struct TwoMaterialBox {
    TetMesh mesh = make_box_mesh({8, 4, 4}, {-2, -1, -1}, {2, 1, 1});
    TetConnectivity connectivity = build_connectivity(mesh);
    std::vector<TetMaterial> materials;
    TwoMaterialBox() {
        for (const Tet& t : mesh.tets) {
            const double x = (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]] + mesh.positions[t[3]]).x();
            materials.push_back(material_preset(x < 0 ? "ketchup" : "apple"));
        }
        mesh.materials = materials;
    }
};

Lighting key_light() {
    Lighting lighting;
    lighting.lights.push_back(default_key_light());
    lighting.ambient = {0.02, 0.02, 0.02};
    return lighting;
}

// A cube's faces are flat: drawn with a uniform E and no highlight, each face must come out as even
// as the perspective allows right up to its edges. One averaged normal per vertex (crease angle 180)
// leans 45 degrees off both faces at an edge; along the silhouette it turns away from the camera and
// F_t(n.v) draws a jagged strip there dark, down to black. The shading surface gives each face's
// copies the face's own normal.
TEST(CreaseShading, ACubesFacesShadeEvenlyUpToTheirEdges) {
    const TetMesh cube = make_box_mesh({5, 5, 5}, {0, 0, 0}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(cube);
    const std::vector<TetMaterial> marble(cube.tet_count(), material_preset("marble"));
    HeadlessGlContext context;
    SurfaceRenderer renderer(context.gl());
    // The spread of luminance over points of the front (z = 1), right (x = 1) and top (y = 1) faces,
    // from 2% of a side away from the edges inwards, worst face. Points whose pixel lies within 2.5
    // pixels of the face's outline are left out: their pixels blend with the neighbouring face or the
    // background.
    const auto face_spread = [&](double crease_angle) {
        const SolvedScene scene = solve_scene(cube, connectivity, marble, key_light(), quick_solve(), crease_angle);
        SurfaceRenderInput input = make_render_input(cube, scene, key_light(), ImageSettings{320, 240, {}, 1.0f});
        std::fill(input.radiance_factor.begin(), input.radiance_factor.end(), std::array<float, 3>{0.3f, 0.3f, 0.3f});
        input.specular_scale = 0;
        const Image image = renderer.render(input);
        const auto on_face = [](int axis, double u, double v) {
            Eigen::Vector3d p;
            p[axis] = 1.0;
            p[(axis + 1) % 3] = u;
            p[(axis + 2) % 3] = v;
            return p;
        };
        const auto distance_to_segment = [](const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
            const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
            return (p - (a + t * (b - a))).norm();
        };
        double worst = 0;
        size_t samples = 0;
        for (int axis : {0, 1, 2}) {
            std::array<Eigen::Vector2d, 4> corners;
            const double square[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int k = 0; k < 4; ++k) corners[k] = project(input, on_face(axis, square[k][0], square[k][1]));
            double lo = 1e9, hi = -1e9;
            for (double u = 0.02; u <= 0.981; u += 0.04)
                for (double v = 0.02; v <= 0.981; v += 0.04) {
                    const Eigen::Vector2d px = project(input, on_face(axis, u, v));
                    double margin = 1e9;
                    for (int k = 0; k < 4; ++k)
                        margin = std::min(margin, distance_to_segment(px, corners[k], corners[(k + 1) % 4]));
                    if (margin < 2.5) continue;
                    const double l = luminance(image, static_cast<int>(px.x()), static_cast<int>(px.y()));
                    lo = std::min(lo, l);
                    hi = std::max(hi, l);
                    ++samples;
                }
            worst = std::max(worst, hi - lo);
        }
        EXPECT_GT(samples, 1000u);
        return worst;
    };
    const double split = face_spread(kDefaultCreaseAngleDegrees), averaged = face_spread(180.0);
    // The perspective changes F_t across a face by a few levels (9 on the top face, seen at a grazing
    // 68 degrees); averaged normals turn away from the camera along the silhouette and draw it black.
    EXPECT_LT(split, 12.0);
    EXPECT_GT(averaged, 100.0);
}

Image render_view(const TetMesh& mesh, const TetConnectivity& connectivity, const std::vector<TetMaterial>& materials,
                  const Lighting& lighting, const ViewOptions& view, SurfaceRenderInput* used = nullptr,
                  const CameraSettings& camera = {}) {
    const SolvedScene scene = solve_scene(mesh, connectivity, materials, lighting, quick_solve());
    ImageSettings settings;
    settings.width = 200;
    settings.height = 150;
    settings.camera = camera;
    SurfaceRenderInput input = make_render_input(mesh, scene, lighting, settings);
    apply_view(build_view_geometry(mesh, connectivity, materials, scene, view), input);
    if (used) *used = input;
    return render_surface(input);
}

TEST(ViewModes, MaterialsViewShowsEachMaterialsHueOnItsSide) {
    const TwoMaterialBox box;
    const SolvedScene scene = solve_scene(box.mesh, box.connectivity, box.materials, key_light(), quick_solve());
    const ViewGeometry view = materials_view(scene.surface, box.materials);
    ASSERT_EQ(view.colours.size(), scene.surface.triangles.size());
    EXPECT_EQ(view.legend.swatches.size(), 2u);
    const auto red = material_colour(material_preset("ketchup")), green = material_colour(material_preset("apple"));
    EXPECT_GT(red[0], 2 * red[1]);    // ketchup is red
    EXPECT_GT(green[1], red[1]);      // apple is not

    SurfaceRenderInput input;
    CameraSettings front;
    front.eye_direction = Eigen::Vector3d(0, 0, 1);
    ViewOptions options;
    options.mode = ViewMode::Materials;
    const Image image = render_view(box.mesh, box.connectivity, box.materials, key_light(), options, &input, front);
    // Left of the centre the front face is red (r well above g), right of it the g/r ratio is higher.
    const Eigen::Vector2d left = project(input, {-1, 0, 1}), right = project(input, {1, 0, 1});
    const uint8_t* l = image.pixel(static_cast<int>(left.x()), static_cast<int>(left.y()));
    const uint8_t* r = image.pixel(static_cast<int>(right.x()), static_cast<int>(right.y()));
    EXPECT_GT(l[0], l[1] + 60);
    EXPECT_GT(static_cast<double>(r[1]) / r[0], static_cast<double>(l[1]) / l[0] + 0.3);
}

TEST(ViewModes, QualityViewColoursABadTetRed) {
    // A regular-ish tet and, apart from it, a sliver: four almost coplanar points.
    std::vector<Eigen::Vector3d> positions = {{0, 0, 0}, {1, 0, 0}, {0.5, 0.87, 0}, {0.5, 0.29, 0.82},
                                              {3, 0, 0}, {4, 0, 0}, {4, 1, 0},       {3, 1, 0.02}};
    const TetMesh mesh = make_tet_mesh(positions, {Tet{0, 1, 2, 3}, Tet{4, 5, 6, 7}});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(2, material_preset("marble"));
    const SolvedScene scene = solve_scene(mesh, connectivity, materials, key_light(), quick_solve());
    const ViewGeometry view = quality_view(mesh, scene.surface);
    ASSERT_EQ(view.colours.size(), 8u);
    for (size_t t = 0; t < view.colours.size(); ++t) {
        const auto& c = view.colours[t];
        if (scene.surface.triangle_tets[t] == 1) {
            EXPECT_EQ(c, quality_colour(0.0)) << "the sliver's faces are red";
        } else {
            EXPECT_GT(c[1], c[0]) << "the good tet's faces are green";
        }
    }
    EXPECT_EQ(view.legend.units, "degrees");

    ViewOptions options;
    options.mode = ViewMode::Quality;
    SurfaceRenderInput input;
    CameraSettings above;
    above.eye_direction = Eigen::Vector3d(0, 0.2, 1);
    const Image image = render_view(mesh, connectivity, materials, key_light(), options, &input, above);
    size_t red = 0, green = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const uint8_t* p = image.pixel(x, y);
            // By hue: the sliver's faces face the camera squarely, so their red is a bright one.
            red += p[0] > 100 && p[0] > 2 * p[1] && p[0] > 2 * p[2];
            green += p[1] > 80 && p[0] < p[1] / 2;
        }
    EXPECT_GT(red, 50u);
    EXPECT_GT(green, 50u);
}

TEST(ViewModes, InteriorQualityColoursTheCrossSectionsSliversRed) {
    TetMesh mesh = make_box_mesh({6, 6, 6}, {-1, -1, -1}, {1, 1, 1});
    const std::vector<int32_t> slivers = flatten_into_slivers(mesh, build_connectivity(mesh), 3, 0.02);
    ASSERT_FALSE(slivers.empty());
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const SolvedScene scene = solve_scene(mesh, connectivity, materials, key_light(), quick_solve());
    // The plane z = the first sliver's centroid, so the section crosses it.
    const Tet& bad = mesh.tets[static_cast<size_t>(slivers.front())];
    const double z = 0.25 * (mesh.positions[bad[0]] + mesh.positions[bad[1]] + mesh.positions[bad[2]] + mesh.positions[bad[3]]).z();
    ViewOptions options;
    options.mode = ViewMode::Quality;
    options.quality_interior = true;
    options.slice_offset = z;  // the box's half extent along z is 1
    const ViewGeometry view = build_view_geometry(mesh, connectivity, materials, scene, options);
    ASSERT_TRUE(view.clip_plane);
    ASSERT_FALSE(view.overlay.triangle_vertices.empty());
    size_t red = 0;
    for (size_t i = 0; i < view.overlay.triangle_colours.size(); ++i) {
        EXPECT_NEAR(view.overlay.triangle_vertices[i].z(), z, 1e-5);
        red += view.overlay.triangle_colours[i] == quality_colour(0.0);
    }
    EXPECT_GT(red, 0u);
    // Only bad tets are red: every red corner lies in (the box of) a tet of at most 5 degrees, and the
    // box mesh had none before the flattening (its Kuhn tets have 45-90 degrees).
    EXPECT_GT(mesh_min_dihedral_deg(make_box_mesh({6, 6, 6}, {-1, -1, -1}, {1, 1, 1})), kQualityRedDeg);
    const std::vector<double> angles = min_dihedral_angles_deg(mesh);
    std::vector<Eigen::AlignedBox3d> bad_boxes;
    for (size_t t = 0; t < mesh.tet_count(); ++t) {
        if (angles[t] > kQualityRedDeg) continue;
        Eigen::AlignedBox3d box;
        for (const int32_t v : mesh.tets[t]) box.extend(mesh.positions[v]);
        bad_boxes.emplace_back(box.min() - Eigen::Vector3d::Constant(1e-6), box.max() + Eigen::Vector3d::Constant(1e-6));
    }
    for (size_t i = 0; i < view.overlay.triangle_colours.size(); ++i) {
        if (view.overlay.triangle_colours[i] != quality_colour(0.0)) continue;
        const Eigen::Vector3d p = view.overlay.triangle_vertices[i].cast<double>();
        EXPECT_TRUE(std::any_of(bad_boxes.begin(), bad_boxes.end(), [&](const auto& box) { return box.contains(p); }))
            << p.transpose();
    }
    // Without the option the quality view is the surface alone.
    options.quality_interior = false;
    const ViewGeometry surface_only = build_view_geometry(mesh, connectivity, materials, scene, options);
    EXPECT_FALSE(surface_only.clip_plane);
    EXPECT_TRUE(surface_only.overlay.empty());
}

TEST(ViewModes, WireframeDrawsEveryTetEdgeOverTheRadiance) {
    const TetMesh mesh = make_box_mesh({3, 3, 3}, {-1, -1, -1}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const ViewGeometry view = wireframe_view(mesh, connectivity);
    EXPECT_EQ(view.overlay.line_vertices.size(), 2 * connectivity.edges.size());
    EXPECT_EQ(view.shading, SurfaceShading::Radiance);

    ViewOptions options;
    const Image radiance = render_view(mesh, connectivity, materials, key_light(), options);
    options.mode = ViewMode::Wireframe;
    const Image wireframe = render_view(mesh, connectivity, materials, key_light(), options);
    size_t darker = 0;
    for (int y = 0; y < radiance.height; ++y)
        for (int x = 0; x < radiance.width; ++x) darker += luminance(wireframe, x, y) + 40 < luminance(radiance, x, y);
    EXPECT_GT(darker, 200u);  // the dark lines cross the lit surface
}

TEST(ViewModes, SliceIsBrighterTowardsTheLightAndTheCutHalfIsGone) {
    const TetMesh mesh = make_box_mesh({8, 4, 4}, {-2, -1, -1}, {2, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("ketchup"));
    Lighting from_right;
    from_right.lights.push_back({LightType::Directional, Eigen::Vector3d(-1, 0, 0), {1, 1, 1}});  // lights x = 2
    ViewOptions options;
    options.mode = ViewMode::Slice;
    options.slice_normal = Eigen::Vector3d(0, 0, 1);
    const SolvedScene scene = solve_scene(mesh, connectivity, materials, from_right, quick_solve());
    const ViewGeometry view = slice_view(mesh, scene.diffusion.phi, options);
    ASSERT_FALSE(view.overlay.triangle_vertices.empty());
    for (const Eigen::Vector3f& p : view.overlay.triangle_vertices) EXPECT_NEAR(p.z(), 0.0f, 1e-5f);
    ASSERT_TRUE(view.clip_plane);

    CameraSettings front;
    front.eye_direction = Eigen::Vector3d(0, 0, 1);
    SurfaceRenderInput input;
    const Image slice = render_view(mesh, connectivity, materials, from_right, options, &input, front);
    // Along the slice's middle line: brighter towards x = 2.
    double previous = -1;
    int rises = 0;
    for (double x : {-1.5, -0.5, 0.5, 1.5}) {
        const Eigen::Vector2d px = project(input, {x, 0, 0});
        const double l = luminance(slice, static_cast<int>(px.x()), static_cast<int>(px.y()));
        rises += l > previous;
        previous = l;
    }
    EXPECT_EQ(rises, 4);

    // Seen from the side (+x), the box is 2 deep in z; the slice keeps z <= 0: half of it.
    CameraSettings side;
    side.eye_direction = Eigen::Vector3d(1, 0, 0);
    ViewOptions radiance;
    SurfaceRenderInput whole_input, cut_input;
    const Image whole = render_view(mesh, connectivity, materials, from_right, radiance, &whole_input, side);
    const Image cut = render_view(mesh, connectivity, materials, from_right, options, &cut_input, side);
    const double ratio = static_cast<double>(covered_pixels(cut, cut_input)) / covered_pixels(whole, whole_input);
    EXPECT_GT(ratio, 0.4);
    EXPECT_LT(ratio, 0.6);
    // Nothing at z > 0 is drawn: the image column of z = 0.5 is background.
    const Eigen::Vector2d gone = project(cut_input, {2, 0, 0.5});
    EXPECT_TRUE(is_background(cut, static_cast<int>(gone.x()), static_cast<int>(gone.y()), cut_input));
}

TEST(ViewModes, LevelsShowSeveralHierarchyLevels) {
    const TetMesh mesh = make_box_mesh({10, 10, 10}, {-1, -1, -1}, {1, 1, 1});
    const TetConnectivity connectivity = build_connectivity(mesh);
    const std::vector<TetMaterial> materials(mesh.tet_count(), material_preset("marble"));
    const std::vector<int32_t> levels = hierarchy_vertex_levels(mesh, connectivity);
    ASSERT_EQ(levels.size(), mesh.vertex_count());
    const int32_t deepest = *std::max_element(levels.begin(), levels.end());
    EXPECT_GE(deepest, 2);
    // Coarser levels keep fewer vertices.
    std::vector<size_t> count(static_cast<size_t>(deepest) + 1, 0);
    for (int32_t l : levels) ++count[static_cast<size_t>(l)];
    for (int32_t l = 1; l <= deepest; ++l) EXPECT_GT(count[l - 1], count[l]);

    ViewOptions options;
    options.mode = ViewMode::Levels;
    const Image image = render_view(mesh, connectivity, materials, key_light(), options);
    std::set<std::array<uint8_t, 3>> hues;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const uint8_t* p = image.pixel(x, y);
            const int spread = std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
            if (spread > 80) hues.insert({static_cast<uint8_t>(p[0] / 64), static_cast<uint8_t>(p[1] / 64),
                                          static_cast<uint8_t>(p[2] / 64)});
        }
    EXPECT_GE(hues.size(), 2u);  // at least two saturated level colours on screen
}

TEST(ViewModes, CacheRebuildsOnlyWhatChanged) {
    const TwoMaterialBox box;
    const SolvedScene scene = solve_scene(box.mesh, box.connectivity, box.materials, key_light(), quick_solve());
    ViewGeometryCache cache;
    ViewOptions options;
    options.mode = ViewMode::Materials;
    const auto first = cache.get(box.mesh, box.connectivity, box.materials, scene, options, 0, 0);
    EXPECT_EQ(cache.get(box.mesh, box.connectivity, box.materials, scene, options, 0, 1), first);  // phi moved: same
    EXPECT_EQ(cache.builds(), 1);
    cache.get(box.mesh, box.connectivity, box.materials, scene, options, 1, 1);  // geometry changed
    EXPECT_EQ(cache.builds(), 2);
    options.mode = ViewMode::Slice;
    cache.get(box.mesh, box.connectivity, box.materials, scene, options, 1, 1);
    cache.get(box.mesh, box.connectivity, box.materials, scene, options, 1, 2);  // the slice shows phi
    EXPECT_EQ(cache.builds(), 4);
}

TEST(RenderShow, EveryViewRendersAndBadOptionsGiveOneLineErrors) {
    const auto dir = testing::scratch_dir("render_show");
    const auto volume = dir / "box.vtu";
    ASSERT_EQ(run_waxwork("mesh " + std::string(WAXWORK_ASSET_DIR) + "/meshes/cube.obj -o " + volume.string() +
                          " --max-tets 3000").exit_code, 0);
    for (ViewMode mode : all_view_modes()) {
        const auto image = dir / (std::string(view_mode_name(mode)) + ".png");
        const auto r = run_waxwork("render " + volume.string() + " -o " + image.string() + " --width 120 --height 90 --show " +
                                   view_mode_name(mode));
        EXPECT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find(std::string("\"view\":\"") + view_mode_name(mode) + "\""), std::string::npos) << r.out;
        EXPECT_TRUE(std::filesystem::exists(image));
    }
    for (const std::string bad : {"--show normals", "--show slice --slice-normal 0,0", "--show slice --slice-normal 0,0,0",
                                  "--show slice --slice-offset 2", "--show slice --slice-offset nan"}) {
        const auto r = run_waxwork("render " + volume.string() + " -o " + (dir / "bad.png").string() + " " + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_EQ(testing::line_count(r.err), 1u) << bad << ": " << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir / "bad.png")) << bad;
    }
}

}  // namespace
}  // namespace waxwork
