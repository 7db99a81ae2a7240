// The example sessions of assets/sessions, replayed on the shipped spot mesh with small images, and
// the image statistics each scene implies.
#include "io/image_io.h"
#include "io/volume_file.h"
#include "render/render_input.h"
#include "scene/session.h"

#include "support/scratch_dir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>

namespace waxwork {
namespace {

namespace fs = std::filesystem;

const fs::path kSessions = fs::path(WAXWORK_ASSET_DIR) / "sessions";
constexpr int kWidth = 240;
constexpr int kHeight = 180;

// Spot meshed once for all tests, the way the sessions mesh it (marble at their scale).
const fs::path& spot_volume() {
    static const fs::path path = [] {
        const fs::path dir = testing::scratch_dir("example_sessions_spot");
        const fs::path volume = dir / "spot.vtu";
        const SessionVolume input = load_session_input(read_session(kSessions / "backlit.json"));
        write_volume(input.mesh, volume, VolumeMetadata{input.scale.mm_per_unit});
        return volume;
    }();
    return path;
}

struct Replay {
    Session session;
    SessionResult result;
    fs::path out;
};

Replay replay(const std::string& name) {
    Replay r;
    r.session = read_session(kSessions / (name + ".json"));
    r.session.input = SessionInput{};
    r.session.input.volume = spot_volume();
    r.session.width = kWidth;
    r.session.height = kHeight;
    r.out = testing::scratch_dir("example_sessions_" + name);
    r.result = run_session(r.session, r.out);
    return r;
}

double luminance(const uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

bool is_background(const Image& image, int x, int y) {
    const uint8_t* p = image.pixel(x, y);
    const uint8_t* b = image.pixel(0, 0);
    return std::abs(p[0] - b[0]) + std::abs(p[1] - b[1]) + std::abs(p[2] - b[2]) < 12;
}

// Not black: the object covers a fair part of the frame and is well exposed.
void expect_visible(const Image& image, const std::string& what) {
    size_t object = 0;
    double sum = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            if (!is_background(image, x, y)) {
                ++object;
                sum += luminance(image.pixel(x, y));
            }
    EXPECT_GT(object, static_cast<size_t>(0.03 * image.width * image.height)) << what;
    ASSERT_GT(object, 0u) << what;
    EXPECT_GT(sum / object, 50) << what;
}

// Mean luminance of the pixels where the boundary vertices selected by `pick` (world position,
// normal) land, counting only vertices facing the camera. Projects with the renderer's framing.
struct RegionSample {
    double mean_luminance = 0;
    size_t pixels = 0;
};
RegionSample sample_region(const Image& image, const TetMesh& mesh, const CameraSettings& camera,
                           const std::function<bool(const Eigen::Vector3d&, const Eigen::Vector3d&)>& pick) {
    const TetConnectivity connectivity = build_connectivity(mesh);
    const BoundarySurface surface = extract_boundary_surface(mesh, connectivity, mesh.materials);
    Eigen::AlignedBox3d box;
    for (const auto& p : surface.positions) box.extend(p.cast<float>().cast<double>());
    const CameraFrame frame = frame_camera(box, camera, static_cast<double>(image.width) / image.height);
    RegionSample sample;
    double sum = 0;
    for (size_t s = 0; s < surface.positions.size(); ++s) {
        const Eigen::Vector3d& p = surface.positions[s];
        if (!pick(p, surface.normals[s])) continue;
        if (surface.normals[s].dot((frame.eye - p).normalized()) < 0.3) continue;
        const Eigen::Vector4d clip = frame.projection * frame.view * p.homogeneous();
        const double x = (clip.x() / clip.w() + 1) / 2 * image.width;
        const double y = (1 - clip.y() / clip.w()) / 2 * image.height;
        if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
        sum += luminance(image.pixel(static_cast<int>(x), static_cast<int>(y)));
        ++sample.pixels;
    }
    sample.mean_luminance = sample.pixels ? sum / sample.pixels : 0;
    return sample;
}

TEST(ExampleSessions, BackLitThinPartsGlowBrighterThanTheThickBody) {
    const Replay r = replay("backlit");
    for (const auto& path : r.result.written) expect_visible(read_png(path), path.string());
    const Image image = read_png(r.out / "backlit_2_converged.png");
    // Ears and horns: everything above y = 0.72 (the head's top is lower). Body: the flank.
    const RegionSample thin = sample_region(image, r.result.mesh, r.session.camera,
                                            [](const Eigen::Vector3d& p, const Eigen::Vector3d&) { return p.y() > 0.72; });
    const RegionSample body = sample_region(image, r.result.mesh, r.session.camera,
                                            [](const Eigen::Vector3d& p, const Eigen::Vector3d&) {
                                                return p.z() > 0.1 && p.z() < 0.7 && p.y() > -0.1 && p.y() < 0.35;
                                            });
    ASSERT_GT(thin.pixels, 5u);
    ASSERT_GT(body.pixels, 5u);
    EXPECT_GT(thin.mean_luminance, 1.3 * body.mean_luminance)
        << "ears/horns " << thin.mean_luminance << ", body " << body.mean_luminance;
}

TEST(ExampleSessions, CutExposesALitCrossSectionAndPaintTakesItsHue) {
    const Replay r = replay("marble_vein");
    const Image section = read_png(r.out / "vein_0_cross_section.png");
    const Image painted = read_png(r.out / "vein_1_painted.png");
    expect_visible(section, "cross-section");
    expect_visible(painted, "painted");
    // The cut face x = 0 faces the camera and the light: it is lit.
    const RegionSample face = sample_region(section, r.result.mesh, r.session.camera,
                                            [](const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
                                                return std::abs(p.x()) < 0.01 && n.x() > 0.9;
                                            });
    ASSERT_GT(face.pixels, 20u);
    EXPECT_GT(face.mean_luminance, 3 * luminance(section.pixel(0, 0)));
    EXPECT_GT(face.mean_luminance, 120);
    // Where the paint changed the picture, the colour moved toward the brush's green.
    size_t changed = 0;
    double green_before = 0, green_after = 0;
    for (int y = 0; y < painted.height; ++y)
        for (int x = 0; x < painted.width; ++x) {
            const uint8_t* a = section.pixel(x, y);
            const uint8_t* b = painted.pixel(x, y);
            if (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) < 24) continue;
            ++changed;
            green_before += a[1] / (a[0] + a[1] + a[2] + 1.0);
            green_after += b[1] / (b[0] + b[1] + b[2] + 1.0);
        }
    ASSERT_GT(changed, 50u);
    EXPECT_GT(green_after / changed, green_before / changed + 0.03);
}

TEST(ExampleSessions, CarvingRendersEveryStageAndSavesTheVolume) {
    const Replay r = replay("carve");
    for (const auto& path : r.result.written) {
        if (path.extension() == ".png") expect_visible(read_png(path), path.string());
    }
    const TetMesh saved = read_volume(r.out / "carved.vtu");
    EXPECT_TRUE(saved == r.result.mesh);
    const TetMesh original = read_volume(spot_volume());
    EXPECT_LT(saved.tet_count(), original.tet_count() * 3 / 4);  // two cuts took a good part away
    ASSERT_GE(r.result.steps.size(), 2u);
    EXPECT_EQ(r.result.steps[1].name, "plane_cut");
    EXPECT_LT(r.result.steps[1].tets, original.tet_count());
}

// Columns of the image that show the object, as runs separated by background: pieces pulled apart
// along the view's horizontal show as separate runs.
int object_column_runs(const Image& image) {
    int runs = 0;
    bool inside = false;
    for (int x = 0; x < image.width; ++x) {
        bool any = false;
        for (int y = 0; y < image.height && !any; ++y) any = !is_background(image, x, y);
        if (any && !inside) ++runs;
        inside = any;
    }
    return runs;
}

TEST(ExampleSessions, FracturedPiecesPullApart) {
    const Replay r = replay("fracture");
    const Image whole = read_png(r.out / "fracture_0_whole.png");
    const Image apart = read_png(r.out / "fracture_1_apart.png");
    expect_visible(whole, "whole");
    expect_visible(apart, "apart");
    EXPECT_EQ(object_column_runs(whole), 1);
    EXPECT_GE(object_column_runs(apart), 2);
    EXPECT_EQ(r.result.mesh.piece_transforms.size(), 3u);
    EXPECT_TRUE(read_volume(r.out / "fractured.vtu") == r.result.mesh);
}

// A slab carved out of spot, its head bent out of the slab's plane: the head swings out (the slab was
// 0.22 thick in x, the bent head reaches far beyond it), the pinned rear stays, and the back light
// through the turned head is seen differently.
TEST(ExampleSessions, BentSlabSwingsItsHeadAndTheLightFollows) {
    const Replay r = replay("bend");
    const Image slab = read_png(r.out / "bend_0_slab.png");
    const Image bent = read_png(r.out / "bend_1_bent.png");
    expect_visible(slab, "slab");
    expect_visible(bent, "bent");
    EXPECT_TRUE(read_volume(r.out / "bent.vtu") == r.result.mesh);
    double head_x = 0, rear_x = 0;
    for (const Eigen::Vector3d& p : r.result.mesh.positions) {
        if (p.z() < -0.4 && p.y() > 0.3) head_x = std::max(head_x, std::abs(p.x()));
        if (p.z() > 0.6) rear_x = std::max(rear_x, std::abs(p.x()));
    }
    EXPECT_GT(head_x, 0.25);
    EXPECT_LT(rear_x, 0.13);
    ASSERT_EQ(slab.width, bent.width);
    double difference = 0;
    for (int y = 0; y < slab.height; ++y)
        for (int x = 0; x < slab.width; ++x)
            difference += std::abs(luminance(slab.pixel(x, y)) - luminance(bent.pixel(x, y)));
    EXPECT_GT(difference / (slab.width * slab.height), 2.0);
}

}  // namespace
}  // namespace waxwork
