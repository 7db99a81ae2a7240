// `waxwork render` and `waxwork demo` end to end: the binary meshes, solves, renders and writes files.
#include "io/image_io.h"
#include "render/srgb.h"
#include "render/surface_renderer.h"
#include "solver/shading_surface.h"
#include "support/cli_run.h"
#include "support/fields_table.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

constexpr const char* kHeader = "x,y,z,boundary,q_r,q_g,q_b,phi_r,phi_g,phi_b,lo_r,lo_g,lo_b";

// Mean lo per channel over boundary vertices whose coordinate `axis` is within 5% of the box of `bound`.
std::array<double, 3> mean_lo_near(const Fields& f, int axis, bool at_max) {
    double lo = 1e300, hi = -1e300;
    for (const auto& r : f.rows) {
        const double c = axis == 0 ? r.x : axis == 1 ? r.y : r.z;
        lo = std::min(lo, c);
        hi = std::max(hi, c);
    }
    const double cut = 0.05 * (hi - lo);
    std::array<double, 3> sum{};
    int count = 0;
    for (const auto& r : f.rows) {
        const double c = axis == 0 ? r.x : axis == 1 ? r.y : r.z;
        if (!r.boundary || (at_max ? c < hi - cut : c > lo + cut)) continue;
        for (int k = 0; k < 3; ++k) sum[k] += r.lo[k];
        ++count;
    }
    EXPECT_GT(count, 0);
    for (double& s : sum) s /= std::max(count, 1);
    return sum;
}

std::array<double, 3> mean_lo(const Fields& f) {
    std::array<double, 3> sum{};
    int count = 0;
    for (const auto& r : f.rows) {
        if (!r.boundary) continue;
        for (int k = 0; k < 3; ++k) sum[k] += r.lo[k];
        ++count;
    }
    for (double& s : sum) s /= std::max(count, 1);
    return sum;
}

// One cube volume for the whole suite (meshing is the slow part).
class Render : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = scratch_dir("render_command");
        volume_ = dir_ / "cube.vtu";
        const auto m = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + volume_.string() + " --max-tets 5000");
        ASSERT_EQ(m.exit_code, 0) << m.err;
        const auto i = run_waxwork("info " + volume_.string());
        ASSERT_EQ(i.exit_code, 0) << i.err;
        vertices_ = nlohmann::json::parse(i.out)["vertices"];
    }
    static fs::path dir_, volume_;
    static size_t vertices_;
};
fs::path Render::dir_, Render::volume_;
size_t Render::vertices_ = 0;

TEST_F(Render, MarbleLitFromPlusXIsBrighterOnThePlusXSide) {
    const fs::path image = dir_ / "marble.png", fields = dir_ / "marble.csv";
    // The cube spans 2 model units: at 10 mm per unit it is 2 cm of marble, several diffusion lengths.
    const auto r = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                               " --material marble --light dir:-1,0,0 --scale 10 --width 160 --height 120 --fields " +
                               fields.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["vertices"], vertices_);
    for (const char* key : {"tets", "iterations", "estimated_error", "assembly_ms", "solve_ms", "lighting_ms",
                            "render_ms", "output", "exposure"})
        EXPECT_TRUE(summary.contains(key)) << key;

    const Image png = read_png(image);
    ASSERT_EQ(png.width, 160);
    ASSERT_EQ(png.height, 120);
    int bright = 0;
    for (int y = 0; y < png.height; ++y)
        for (int x = 0; x < png.width; ++x) bright += png.pixel(x, y)[0] > 80;
    EXPECT_GT(bright, png.width * png.height / 20) << "the image is (nearly) black";

    const Fields f = read_fields(fields);
    EXPECT_EQ(f.header, kHeader);
    EXPECT_EQ(f.rows.size(), vertices_);
    EXPECT_TRUE(f.all_finite);
    const auto lit = mean_lo_near(f, 0, true), dark = mean_lo_near(f, 0, false);
    for (int c = 0; c < 3; ++c) EXPECT_GT(lit[c], 3 * dark[c]) << "channel " << c;
    // Interior vertices carry no q or lo; every q and lo is non-negative.
    for (const auto& row : f.rows) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(row.lo[c], 0);
            EXPECT_GE(row.q[c], 0);
            if (!row.boundary) {
                EXPECT_EQ(row.q[c], 0);
                EXPECT_EQ(row.lo[c], 0);
            }
        }
    }
}

// The sky's sun stands low in +x (azimuth 90 from +z): that side glows, the other is lit by the sky
// and the ground alone, and no default key light or ambient is added.
TEST_F(Render, SkyEnvironmentLightsTheSideOfItsSun) {
    const fs::path image = dir_ / "sky.png", fields = dir_ / "sky.csv";
    const auto r = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                               " --material marble --env sky:20,90 --scale 10 --width 80 --height 60 --fields " +
                               fields.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["lights"], 0);
    const Fields f = read_fields(fields);
    const auto sunny = mean_lo_near(f, 0, true), shaded = mean_lo_near(f, 0, false);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(sunny[c], 2 * shaded[c]) << "channel " << c;
        EXPECT_GT(shaded[c], 0) << "the sky lights the side away from the sun";
    }
    // Rotating the environment by 180 degrees puts the sun on the other side.
    const auto turned = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                                    " --material marble --env sky:20,90:180 --scale 10 --width 80 --height 60 --fields " +
                                    fields.string());
    ASSERT_EQ(turned.exit_code, 0) << turned.err;
    const Fields g = read_fields(fields);
    EXPECT_GT(mean_lo_near(g, 0, false)[0], 2 * mean_lo_near(g, 0, true)[0]);
    // The sky is drawn behind the model, unless told not: seen level, the upper corners show the sky
    // (blue, not the plain background).
    const auto level = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                                   " --material marble --env sky:20,90 --view 1,0,0 --scale 10 --width 80 --height 60");
    ASSERT_EQ(level.exit_code, 0) << level.err;
    const Image with_sky = read_png(image);
    const uint8_t* corner = with_sky.pixel(0, 0);
    EXPECT_GT(corner[2], corner[0]) << "a clear sky is bluer than it is red";
    const std::array<uint8_t, 3> plain = SurfaceRenderInput{}.background;
    EXPECT_NE(std::vector<uint8_t>(corner, corner + 3), std::vector<uint8_t>(plain.begin(), plain.end()));
    const auto hidden = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                                    " --material marble --env sky:20,90 --no-env-background --scale 10 --width 80 "
                                    "--height 60");
    ASSERT_EQ(hidden.exit_code, 0) << hidden.err;
    const uint8_t* bare = read_png(image).pixel(0, 0);
    EXPECT_EQ(std::vector<uint8_t>(bare, bare + 3), std::vector<uint8_t>(plain.begin(), plain.end()));
}

TEST_F(Render, FemAgreesWithTransCut) {
    // Marble at 10 mm per unit: the diffusion length (3.9-8.5 mm) spans several edges (about 1.2 mm),
    // where the two discretisations must agree; on an under-resolved mesh they legitimately differ.
    const std::string common = volume_.string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 10 "
                                                  "--width 64 --height 48 --tol 1e-6";
    const auto a = run_waxwork("render " + common + " -o " + (dir_ / "t.png").string() + " --fields " +
                               (dir_ / "t.csv").string());
    const auto b = run_waxwork("render " + common + " --method fem -o " + (dir_ / "f.png").string() + " --fields " +
                               (dir_ / "f.csv").string());
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const Fields t = read_fields(dir_ / "t.csv"), f = read_fields(dir_ / "f.csv");
    ASSERT_EQ(t.rows.size(), f.rows.size());
    // Lumped and consistent mass differ by O(h^2): compare phi in the energy-like mean over vertices.
    for (int c = 0; c < 3; ++c) {
        double diff = 0, norm = 0;
        for (size_t v = 0; v < t.rows.size(); ++v) {
            diff += std::abs(t.rows[v].phi[c] - f.rows[v].phi[c]);
            norm += std::abs(t.rows[v].phi[c]);
        }
        ASSERT_GT(norm, 0);
        EXPECT_LT(diff / norm, 0.05) << "channel " << c;
    }
}

// The seeds' methods solve the same light as TransCut (docs/methods.md): on the cube in marble at
// 10 mm per unit every one of them writes the same --fields columns, lights the same side, and comes
// within its own accuracy of TransCut's fluence at the boundary, which is what the image shows. The
// dipole is a semi-infinite approximation, so its bound is the loosest.
TEST_F(Render, SeedsMethodsWriteTheSameFieldsAndAgreeWithTransCut) {
    const std::string common = volume_.string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 10 "
                                                  "--width 64 --height 48";
    const auto t = run_waxwork("render " + common + " --tol 1e-6 -o " + (dir_ / "tm.png").string() + " --fields " +
                               (dir_ / "tm.csv").string());
    ASSERT_EQ(t.exit_code, 0) << t.err;
    const Fields reference = read_fields(dir_ / "tm.csv");
    for (const auto& [method, bound] : std::vector<std::pair<std::string, double>>{
             {"fd", 0.15}, {"fd-cg", 0.15}, {"fvm", 0.1}, {"fvm-cg", 0.1}, {"lbm", 0.15}, {"dipole", 0.4}}) {
        const fs::path csv = dir_ / ("m_" + method + ".csv");
        const auto r = run_waxwork("render " + common + " --method " + method + " -o " +
                                   (dir_ / ("m_" + method + ".png")).string() + " --fields " + csv.string());
        ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
        const nlohmann::json summary = nlohmann::json::parse(r.out);
        EXPECT_EQ(summary["method"], method);
        EXPECT_GT(summary["alternative"]["unknowns"].get<size_t>(), 0u) << method;
        EXPECT_FALSE(summary.contains("estimated_error")) << method;
        const Fields f = read_fields(csv);
        ASSERT_EQ(f.rows.size(), reference.rows.size()) << method;
        double diff = 0, norm = 0;
        for (size_t v = 0; v < f.rows.size(); ++v) {
            if (!f.rows[v].boundary) continue;
            for (int c = 0; c < 3; ++c) {
                ASSERT_TRUE(std::isfinite(f.rows[v].phi[c])) << method;
                diff += std::abs(f.rows[v].phi[c] - reference.rows[v].phi[c]);
                norm += std::abs(reference.rows[v].phi[c]);
            }
        }
        EXPECT_LT(diff / norm, bound) << method;
        // The light travels towards -x, so it comes from +x: that side is brighter for every method.
        EXPECT_GT(mean_lo_near(f, 0, true)[0], 2 * mean_lo_near(f, 0, false)[0]) << method;
    }
}

TEST_F(Render, SeedsMethodsBadOptionsAreOneLineErrors) {
    const std::string base = "render " + volume_.string() + " -o " + (dir_ / "mbad.png").string() +
                             " --width 32 --height 24 ";
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {"--method quadgraph", "--method: quadgraph not in"},
             {"--method fvm --cell 1", "--cell applies only to the grid methods"},
             {"--cell 1", "--cell applies only to the grid methods"},
             {"--method fd --cell 0", "--cell must be a voxel size in mm"},
             {"--method lbm --cell nan", "--cell must be a voxel size in mm"},
             {"--method fd --cell -2", "--cell must be a voxel size in mm"},
             {"--method dipole --backend gpu", "--method dipole runs on the CPU"},
             {"--method fd --tol 2", "--tol must be a relative tolerance"}}) {
        const auto r = run_waxwork(base + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "mbad.png"));
}

TEST_F(Render, MonteCarloWritesPhiWithStandardErrors) {
    // A 4 mm cube of marble (2 model units at 2 mm per unit) traced to 5% relative standard error at the
    // boundary: the fields gain the standard errors, the seed makes the run repeatable, and the traced
    // fluence is the diffusion's within what the two models legitimately differ by near a lit surface.
    const std::string common = volume_.string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 2 "
                                                  "--width 64 --height 48 --method mc --mc-error 0.05 --mc-seconds 8";
    const auto a = run_waxwork("render " + common + " -o " + (dir_ / "mc.png").string() + " --fields " +
                               (dir_ / "mc.csv").string());
    ASSERT_EQ(a.exit_code, 0) << a.err;
    const auto summary = nlohmann::json::parse(a.out);
    EXPECT_EQ(summary["method"], "mc");
    const auto& mc = summary["monte_carlo"];
    EXPECT_EQ(mc["stopped_by"], "error") << a.out;
    EXPECT_EQ(mc["seed"], 1);
    EXPECT_EQ(mc["lost_photons"], 0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_LE(mc["relative_error"][c].get<double>(), 0.05);
        EXPECT_NEAR(mc["over_diffusion"][c].get<double>(), 1.0, 0.3) << a.out;
    }
    const Fields f = read_fields(dir_ / "mc.csv");
    EXPECT_EQ(f.header, std::string(kHeader) + ",phi_err_r,phi_err_g,phi_err_b");
    EXPECT_TRUE(f.all_finite);
    ASSERT_EQ(f.rows.size(), vertices_);
    for (const auto& r : f.rows) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_GT(r.phi[c], 0);
            EXPECT_GT(r.phi_err[c], 0);
            EXPECT_LT(r.phi_err[c], r.phi[c]);
        }
    }
    EXPECT_TRUE(fs::exists(dir_ / "mc.png"));
    // The same seed, the same fluence; the trace is bit-identical on any thread count.
    const auto b = run_waxwork("render " + common + " -o " + (dir_ / "mc2.png").string() + " --fields " +
                               (dir_ / "mc2.csv").string());
    ASSERT_EQ(b.exit_code, 0) << b.err;
    const Fields g = read_fields(dir_ / "mc2.csv");
    ASSERT_EQ(g.rows.size(), f.rows.size());
    for (size_t v = 0; v < f.rows.size(); ++v) EXPECT_EQ(g.rows[v].phi, f.rows[v].phi);
}

TEST_F(Render, MonteCarloImageFromCameraRaysIsTheSameForASeed) {
    // The written image is traced with camera rays to a path budget: the same seed gives the same PNG,
    // another seed a different one; the summary compares it with the Eq. 3 images.
    const std::string common = volume_.string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 2 "
                                                  "--width 48 --height 36 --method mc --mc-photons 6000";
    const auto a = run_waxwork("render " + common + " -o " + (dir_ / "mci.png").string());
    const auto b = run_waxwork("render " + common + " -o " + (dir_ / "mci2.png").string());
    const auto c = run_waxwork("render " + common + " --seed 2 -o " + (dir_ / "mci3.png").string());
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const auto image = nlohmann::json::parse(a.out)["monte_carlo_image"];
    EXPECT_EQ(image["stopped_by"], "photons") << a.out;
    EXPECT_GE(image["paths_per_channel"].get<int64_t>(), 6000);
    EXPECT_EQ(image["lost_paths"], 0);
    for (int k = 0; k < 3; ++k) {
        EXPECT_GT(image["relative_error"][k].get<double>(), 0);
        EXPECT_GT(image["over_eq3"][k].get<double>(), 0);
        EXPECT_GT(image["over_diffusion"][k].get<double>(), 0);
    }
    const Image first = read_png(dir_ / "mci.png");
    EXPECT_EQ(first, read_png(dir_ / "mci2.png"));
    EXPECT_NE(first, read_png(dir_ / "mci3.png"));
    // The object is drawn over the background: some pixels differ from the corner's.
    const uint8_t* corner = first.pixel(0, 0);
    int object = 0;
    for (int y = 0; y < first.height; ++y)
        for (int x = 0; x < first.width; ++x) object += first.pixel(x, y)[1] != corner[1];
    EXPECT_GT(object, first.width * first.height / 10);
}

TEST_F(Render, MonteCarloStopsAtItsTimeBudgetShowingItsError) {
    // An error target out of reach: the time budget stops the trace, and the status line (rewritten
    // each second, blanked at the end) showed the current error meanwhile.
    const auto r = run_waxwork("render " + volume_.string() + " -o " + (dir_ / "mct.png").string() +
                               " --material marble --scale 2 --width 32 --height 24 --method mc --mc-error 0.0001 "
                               "--mc-seconds 2.5 --seed 3");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto mc = nlohmann::json::parse(r.out)["monte_carlo"];
    EXPECT_EQ(mc["stopped_by"], "seconds");
    // A quarter of the budget for the fluence, the rest for the image.
    EXPECT_GE(mc["seconds"].get<double>(), 0.25 * 2.5);
    const auto image = nlohmann::json::parse(r.out)["monte_carlo_image"];
    EXPECT_EQ(image["stopped_by"], "seconds");
    EXPECT_GE(mc["seconds"].get<double>() + image["seconds"].get<double>(), 2.5);
    EXPECT_EQ(mc["seed"], 3);
    EXPECT_NE(r.err.find("monte carlo: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("relative error"), std::string::npos) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.back(), '\r') << r.err;  // blanked: the next output starts on a clean line
}

TEST_F(Render, MonteCarloBadInputIsAOneLineError) {
    const std::string base = "render " + volume_.string() + " -o " + (dir_ / "mcbad.png").string() +
                             " --width 32 --height 24 ";
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {"--method mc --mc-seconds 0", "--mc-seconds must be a positive, finite number of seconds"},
             {"--method mc --mc-seconds -1", "--mc-seconds must be a positive, finite number of seconds"},
             {"--method mc --mc-seconds nan", "--mc-seconds must be a positive, finite number of seconds"},
             {"--method mc --mc-error 0", "--mc-error must be a relative standard error in (0, 1)"},
             {"--method mc --mc-error nan", "--mc-error must be a relative standard error in (0, 1)"},
             {"--method mc --mc-error 1", "--mc-error must be a relative standard error in (0, 1)"},
             {"--method mc --mc-g 1", "--mc-g must be a Henyey-Greenstein anisotropy in (-1, 1)"},
             {"--method mc --mc-photons 0", "--mc-photons must be a positive number of paths"},
             {"--mc-photons 1000", "apply only with --method mc"},
             {"--seed 3", "apply only with --method mc"},
             {"--method fem --mc-seconds 3", "apply only with --method mc"}}) {
        const auto r = run_waxwork(base + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir_ / "mcbad.png"));
}

TEST_F(Render, GpuBackendAgreesWithTheCpuAndFallsBackWithAWarning) {
    const std::string common = volume_.string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 10 "
                                                  "--width 64 --height 48";
    const auto cpu = run_waxwork("render " + common + " --tol 1e-8 -o " + (dir_ / "c.png").string() + " --fields " +
                                 (dir_ / "c.csv").string());
    const auto gpu = run_waxwork("render " + common + " --tol 1e-5 --backend gpu -o " + (dir_ / "g.png").string() +
                                 " --fields " + (dir_ / "g.csv").string());
    ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
    ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
    EXPECT_EQ(nlohmann::json::parse(cpu.out)["backend"], "cpu");
    EXPECT_EQ(nlohmann::json::parse(gpu.out)["backend"], "gpu") << gpu.err;
    EXPECT_TRUE(gpu.err.empty()) << gpu.err;
    const Fields c = read_fields(dir_ / "c.csv"), g = read_fields(dir_ / "g.csv");
    ASSERT_EQ(c.rows.size(), g.rows.size());
    for (int ch = 0; ch < 3; ++ch) {
        double diff = 0, peak = 0;
        for (size_t v = 0; v < c.rows.size(); ++v) {
            diff = std::max(diff, std::abs(c.rows[v].phi[ch] - g.rows[v].phi[ch]));
            peak = std::max(peak, std::abs(c.rows[v].phi[ch]));
        }
        ASSERT_GT(peak, 0);
        EXPECT_LT(diff / peak, 1e-4) << "channel " << ch;
    }

    // A driver that rejects a shader: one warning line naming it, and the CPU result.
    setenv("WAXWORK_GPU_FORCE_FAIL", "1", 1);
    const auto fallback = run_waxwork("render " + common + " --backend gpu -o " + (dir_ / "f.png").string());
    unsetenv("WAXWORK_GPU_FORCE_FAIL");
    ASSERT_EQ(fallback.exit_code, 0) << fallback.err;
    EXPECT_EQ(nlohmann::json::parse(fallback.out)["backend"], "cpu");
    EXPECT_EQ(line_count(fallback.err), 1u) << fallback.err;
    EXPECT_NE(fallback.err.find("solving on the CPU instead"), std::string::npos) << fallback.err;
    EXPECT_NE(fallback.err.find("failed to compile"), std::string::npos) << fallback.err;

    // A tolerance float CG cannot reach: the CPU finishes in double from the GPU's phi, with one
    // warning line, and reaches the CPU's answer.
    const auto tight = run_waxwork("render " + common + " --tol 1e-12 --backend gpu -o " + (dir_ / "t.png").string() +
                                   " --fields " + (dir_ / "t.csv").string());
    ASSERT_EQ(tight.exit_code, 0) << tight.err;
    EXPECT_EQ(nlohmann::json::parse(tight.out)["backend"], "cpu");
    EXPECT_EQ(line_count(tight.err), 1u) << tight.err;
    EXPECT_NE(tight.err.find("float CG on the GPU stopped at an estimated error of"), std::string::npos) << tight.err;
    const Fields t = read_fields(dir_ / "t.csv");
    for (int ch = 0; ch < 3; ++ch) {
        double diff = 0, peak = 0;
        for (size_t v = 0; v < c.rows.size(); ++v) {
            diff = std::max(diff, std::abs(c.rows[v].phi[ch] - t.rows[v].phi[ch]));
            peak = std::max(peak, std::abs(c.rows[v].phi[ch]));
        }
        EXPECT_LT(diff / peak, 1e-6) << "channel " << ch;
    }
}

TEST_F(Render, StoredMaterialsAreUsedWithoutAMaterialOption) {
    const fs::path ketchup = dir_ / "ketchup.vtu";
    const auto m = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + ketchup.string() +
                               " --max-tets 3000 --material ketchup");
    ASSERT_EQ(m.exit_code, 0) << m.err;
    const std::string args = " --light dir:0,0,-1 --scale 10 --width 64 --height 48";
    const auto k = run_waxwork("render " + ketchup.string() + " -o " + (dir_ / "k.png").string() + " --fields " +
                               (dir_ / "k.csv").string() + args);
    const auto w = run_waxwork("render " + ketchup.string() + " --material marble -o " + (dir_ / "w.png").string() +
                               " --fields " + (dir_ / "w.csv").string() + args);
    ASSERT_EQ(k.exit_code, 0) << k.err;
    ASSERT_EQ(w.exit_code, 0) << w.err;
    EXPECT_EQ(nlohmann::json::parse(k.out)["materials"], "stored");
    const auto red = mean_lo(read_fields(dir_ / "k.csv")), white = mean_lo(read_fields(dir_ / "w.csv"));
    ASSERT_GT(red[2], 0);
    ASSERT_GT(white[2], 0);
    EXPECT_GT(red[0] / red[2], 3 * white[0] / white[2]);
}

TEST_F(Render, BackLitThinSlabGlowsMoreThanAThickOne) {
    // The same cube at two scales: 1 mm per unit (2 mm of skin) passes light through; 40 (8 cm) does not.
    std::array<double, 2> back{};
    for (int i = 0; i < 2; ++i) {
        const fs::path fields = dir_ / ("slab" + std::to_string(i) + ".csv");
        const auto r = run_waxwork("render " + volume_.string() + " --material skin1 --light dir:1,0,0 --scale " +
                                   (i == 0 ? "1" : "40") + " --ambient 0 --width 32 --height 24 -o " +
                                   (dir_ / "slab.png").string() + " --fields " + fields.string());
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const Fields f = read_fields(fields);
        const auto far = mean_lo_near(f, 0, true), near = mean_lo_near(f, 0, false);
        back[i] = far[0] / near[0];  // red: transmitted over reflected
    }
    EXPECT_GT(back[0], 10 * back[1]);
}

TEST_F(Render, PointLightInsideTheObjectLightsNothing) {
    const fs::path fields = dir_ / "inside.csv";
    const auto r = run_waxwork("render " + volume_.string() + " --light point:0,0,0 --ambient 0 --width 32 --height 24 -o " +
                               (dir_ / "inside.png").string() + " --fields " + fields.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["lights_inside"], 1);
    const Fields f = read_fields(fields);
    EXPECT_TRUE(f.all_finite);
    for (const auto& row : f.rows)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(row.lo[c], 0);
}

// The cube spans [-1, 1]^3: a sphere light off its +x face lights that side; one centred inside lights
// nothing, and is counted as a point light inside would be.
TEST_F(Render, SphereLightLightsItsSideAndNothingFromInside) {
    const fs::path fields = dir_ / "sphere.csv";
    const auto r = run_waxwork("render " + volume_.string() + " --light sphere:2.5,0.2,0:0.5:8,8,8 --ambient 0 --scale 10 " +
                               "--width 48 --height 36 -o " + (dir_ / "sphere.png").string() + " --fields " + fields.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["lights_inside"], 0);
    EXPECT_TRUE(fs::exists(dir_ / "sphere.png"));
    const Fields f = read_fields(fields);
    EXPECT_TRUE(f.all_finite);
    const auto lit = mean_lo_near(f, 0, true), dark = mean_lo_near(f, 0, false);
    EXPECT_GT(lit[0], 10 * dark[0]);

    const fs::path inside_fields = dir_ / "sphere_inside.csv";
    const auto inside = run_waxwork("render " + volume_.string() + " --light sphere:0,0,0:0.3 --ambient 0 --width 32 " +
                                    "--height 24 -o " + (dir_ / "sphere_inside.png").string() + " --fields " +
                                    inside_fields.string());
    ASSERT_EQ(inside.exit_code, 0) << inside.err;
    EXPECT_EQ(nlohmann::json::parse(inside.out)["lights_inside"], 1);
    for (const auto& row : read_fields(inside_fields).rows)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(row.lo[c], 0);

    const auto bad = run_waxwork("render " + volume_.string() + " --light sphere:3,0,0:0 -o " + (dir_ / "bad.png").string());
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_NE(bad.err.find("bad light spec 'sphere:3,0,0:0': radius must be finite and positive"), std::string::npos) << bad.err;
}

// The cube's edges are creases: the summary counts the copies the image shades them with, and 180
// degrees (one normal per vertex) makes none. The solve's light differs exactly along the edges, where
// the split integrates each face's own light (source_light).
TEST_F(Render, CreaseAngleSplitsTheCubesEdgesForTheImageAndTheSource) {
    const std::string base = "render " + volume_.string() + " --width 64 --height 48 -o " + (dir_ / "crease.png").string();
    const fs::path split_fields = dir_ / "split.csv", unsplit_fields = dir_ / "unsplit.csv";
    const auto split = run_waxwork(base + " --fields " + split_fields.string());
    const auto unsplit = run_waxwork(base + " --crease-angle 180 --fields " + unsplit_fields.string());
    ASSERT_EQ(split.exit_code, 0) << split.err;
    ASSERT_EQ(unsplit.exit_code, 0) << unsplit.err;
    const auto a = nlohmann::json::parse(split.out), b = nlohmann::json::parse(unsplit.out);
    EXPECT_EQ(a["crease_angle_deg"], kDefaultCreaseAngleDegrees);
    EXPECT_GT(a["shading_copies"].get<int>(), 0);
    EXPECT_EQ(b["shading_copies"], 0);

    const Fields fa = read_fields(split_fields), fb = read_fields(unsplit_fields);
    ASSERT_EQ(fa.rows.size(), fb.rows.size());
    Eigen::AlignedBox3d box;
    for (const auto& r : fa.rows) box.extend(Eigen::Vector3d(r.x, r.y, r.z));
    size_t moved = 0;
    for (size_t v = 0; v < fa.rows.size(); ++v) {
        const FieldRow &ra = fa.rows[v], &rb = fb.rows[v];
        const Eigen::Vector3d p(ra.x, ra.y, ra.z);
        int faces = 0;  // the cube's faces the vertex lies on
        for (int k = 0; k < 3; ++k)
            faces += std::abs(p[k] - box.min()[k]) < 1e-6 * box.diagonal().norm() ||
                     std::abs(p[k] - box.max()[k]) < 1e-6 * box.diagonal().norm();
        if (ra.q != rb.q) {
            ++moved;
            EXPECT_GE(faces, 2) << "light moved off the edges at " << p.transpose();
        }
    }
    EXPECT_GT(moved, 0u);
}

TEST_F(Render, BadInputIsAOneLineError) {
    const fs::path image = dir_ / "bad.png";
    const std::string base = "render " + volume_.string() + " -o " + image.string() + " --width 32 --height 24";
    for (const std::string args :
         {" --light dir:1,0", " --light spot:0,0,1", " --light dir:1,0,0:1,1", " --light dir:0,0,0",
          " --light dir:1,0,0:-1,1,1", " --light dir:1,x,0", " --light point:1,2,3extra", " --material unobtainium",
          " --mua 0.1,0.1,0.1 --musp 0,1,1 --eta 1.3", " --mua nan,0.1,0.1 --musp 1,1,1 --eta 1.3", " --tol nan",
          " --width 0", " --height -5", " --width 20000", " --width 8193", " --scale 0", " --scale -3", " --scale inf",
          " --scale 1e300",
          " --method magic", " --view 0,0,0", " --exposure -1"}) {
        const auto r = run_waxwork(base + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
        EXPECT_EQ(r.err.rfind("waxwork: ", 0), 0u) << r.err;
    }
    // Values whose squares overflow are refused by what they are, not by a solver failing on them.
    for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
             {" --tol 1e-300", "--tol must be a relative tolerance in [1e-15, 1)"},
             {" --ambient 1e308", "--ambient must be non-negative and at most 1e15"},
             {" --light dir:1,0,0:1e308,1,1", "intensity must be non-negative and at most 1e15"},
             {" --light dir:1,0,0:1e16,1,1", "intensity must be non-negative and at most 1e15"},
             {" --light point:1e308,0,0", "position has a non-finite component or one beyond 1e100"},
             {" --crease-angle 181", "--crease-angle must be between 0 and 180 degrees"},
             {" --crease-angle nan", "--crease-angle must be between 0 and 180 degrees"},
             {" --exposure 1e308", "--exposure must be positive and at most 1e30"},
             {" --env sky:95,0", "bad environment spec 'sky:95,0': sky: sun elevation must be above 0"},
             {" --no-env-background", "--no-env-background needs --env"},
             {" --background 256,0,0", "background '256,0,0': expected R,G,B (0-255), #RRGGBB, transparent or environment"},
             {" --background '#12345'", "background '#12345': expected"},
             {" --background 1,2", "background '1,2': expected"},
             {" --background environment", "--background environment needs --env"},
             {" --linear x.jpg", "--linear x.jpg: the linear image is a 16-bit .png"},
             {" --ground --show materials", "--ground applies only to --show radiance"},
             {" --env studio.hdr:0:-2", "the intensity must be a number between 0 and 1e15"},
             {" --env " + (dir_ / "absent.hdr").string(), (dir_ / "absent.hdr").string() + ": no such file"},
             {" --env " + volume_.string(), volume_.string() + ": not a Radiance .hdr image"}}) {
        const auto r = run_waxwork(base + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    }
    // The format follows the name, so the name must be one of them.
    const fs::path bmp = image.parent_path() / "x.bmp";
    const auto named_bmp = run_waxwork("render " + volume_.string() + " -o " + bmp.string() + " --width 32 --height 24");
    EXPECT_NE(named_bmp.exit_code, 0);
    EXPECT_NE(named_bmp.err.find(bmp.string() + ": the image must be a .png, .jpg or .jpeg"), std::string::npos)
        << named_bmp.err;
    EXPECT_FALSE(fs::exists(bmp));
    // A huge view direction is still a direction.
    EXPECT_EQ(run_waxwork(base + " --view 1e308,1e308,1e308").exit_code, 0);
    fs::remove(image);
    const auto light = run_waxwork(base + " --light dir:1,0");
    EXPECT_NE(light.err.find("dir:1,0"), std::string::npos) << light.err;
    EXPECT_FALSE(fs::exists(image));
    const auto missing = run_waxwork("render " + (dir_ / "absent.vtu").string() + " -o " + image.string());
    EXPECT_NE(missing.exit_code, 0);
    EXPECT_NE(missing.err.find("absent.vtu"), std::string::npos) << missing.err;
}

// The image's four corners, which the cube (framed with a margin) never covers.
std::vector<const uint8_t*> corners(const Image& image) {
    return {image.pixel(0, 0), image.pixel(image.width - 1, 0), image.pixel(0, image.height - 1),
            image.pixel(image.width - 1, image.height - 1)};
}

TEST_F(Render, TransparentBackgroundIsAlphaZeroAroundTheObjectAndOpaqueOnIt) {
    const fs::path image = dir_ / "transparent.png";
    const auto r = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                               " --width 64 --height 48 --background transparent");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image png = read_png(image);
    for (const uint8_t* p : corners(png)) EXPECT_EQ(p[3], 0);
    const uint8_t* centre = png.pixel(32, 24);
    EXPECT_EQ(centre[3], 255);
    EXPECT_GT(centre[0] + centre[1] + centre[2], 0);
    // The multisampled edges give partial coverage.
    size_t partial = 0;
    for (size_t p = 3; p < png.rgba.size(); p += 4) partial += png.rgba[p] > 0 && png.rgba[p] < 255;
    EXPECT_GT(partial, 0u);
    // The same render over the default grey is the same where the object covers everything.
    const fs::path grey = dir_ / "grey.png";
    ASSERT_EQ(run_waxwork("render " + volume_.string() + " -o " + grey.string() + " --width 64 --height 48").exit_code, 0);
    const Image opaque = read_png(grey);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(opaque.pixel(32, 24)[c], centre[c]);
    EXPECT_EQ(opaque.pixel(0, 0)[3], 255);
}

TEST_F(Render, ColourBackgroundFillsTheCorners) {
    for (const auto& [words, colour] : std::vector<std::pair<std::string, std::array<int, 3>>>{
             {"200,30,7", {200, 30, 7}}, {"'#1a2B3c'", {0x1a, 0x2b, 0x3c}}}) {
        const fs::path image = dir_ / "coloured.png";
        const auto r = run_waxwork("render " + volume_.string() + " -o " + image.string() +
                                   " --width 64 --height 48 --background " + words);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const Image png = read_png(image);
        for (const uint8_t* p : corners(png)) {
            EXPECT_EQ(p[0], colour[0]) << words;
            EXPECT_EQ(p[1], colour[1]) << words;
            EXPECT_EQ(p[2], colour[2]) << words;
            EXPECT_EQ(p[3], 255) << words;
        }
    }
    // A colour background replaces the environment's.
    const fs::path sky = dir_ / "sky_white.png";
    const auto r = run_waxwork("render " + volume_.string() + " -o " + sky.string() +
                               " --width 64 --height 48 --env sky:30,40 --background 255,255,255");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Image sky_image = read_png(sky);  // named: corners() points into it
    for (const uint8_t* p : corners(sky_image)) EXPECT_EQ(p[0] + p[1] + p[2], 3 * 255);
}

TEST_F(Render, JpegIsWrittenAndReadsBackAtTheSameSize) {
    const fs::path png = dir_ / "same.png", jpg = dir_ / "same.JPG";
    const std::string base = "render " + volume_.string() + " --width 70 --height 50 -o ";
    const std::string orange = " --background 240,120,20";
    ASSERT_EQ(run_waxwork(base + png.string() + orange).exit_code, 0);
    const auto r = run_waxwork(base + jpg.string() + orange);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(jpg, std::ios::binary);
    char magic[3] = {};
    in.read(magic, 3);
    EXPECT_EQ(static_cast<unsigned char>(magic[0]), 0xFF);  // the JPEG SOI marker, not a PNG under another name
    EXPECT_EQ(static_cast<unsigned char>(magic[1]), 0xD8);
    const Image a = read_png(png), b = read_image(jpg);
    ASSERT_EQ(b.width, 70);
    ASSERT_EQ(b.height, 50);
    // Quality 92: close to the PNG everywhere on average, the corners' flat colour within a few levels.
    double error = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) error += std::abs(a.rgba[i] - b.rgba[i]);
    EXPECT_LT(error / a.rgba.size(), 3.0);
    EXPECT_NEAR(b.pixel(0, 0)[0], 240, 4);
    EXPECT_NEAR(b.pixel(0, 0)[1], 120, 4);
    EXPECT_NEAR(b.pixel(0, 0)[2], 20, 4);
    // JPEG has no alpha to be transparent with.
    const auto t = run_waxwork(base + jpg.string() + " --background transparent");
    EXPECT_NE(t.exit_code, 0);
    EXPECT_NE(t.err.find("--background transparent needs a .png output"), std::string::npos) << t.err;
}

TEST_F(Render, LinearPngHoldsTheRadianceTheToneMapReceives) {
    const fs::path image = dir_ / "toned.png", linear = dir_ / "linear.png";
    const auto r = run_waxwork("render " + volume_.string() + " -o " + image.string() + " --linear " + linear.string() +
                               " --width 64 --height 48 --background transparent");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["linear"], linear.string());
    const Image toned = read_png(image);
    const LinearImage radiance = read_linear_png(linear);
    ASSERT_EQ(radiance.width, 64);
    ASSERT_EQ(radiance.height, 48);
    // ACES (Narkowicz's fit) then sRGB of the linear pixel gives the 8-bit pixel, at fully covered
    // pixels whose radiance is below the 16-bit file's clamp at 1, away from the cube's edges (there
    // the multisample resolve averages before tone mapping in one image and after it in the other).
    auto aces = [](double x) { return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); };
    size_t compared = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
            const float* l = radiance.pixel(x, y);
            const uint8_t* t = toned.pixel(x, y);
            EXPECT_EQ(std::lround(255 * l[3]), t[3]);
            if (t[3] != 255 || std::max({l[0], l[1], l[2]}) >= 1.0f || x == 0 || y == 0 || x == 63 || y == 47) continue;
            bool smooth = true;
            for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}})
                for (int c = 0; c < 4; ++c) smooth = smooth && std::abs(toned.pixel(x + dx, y + dy)[c] - t[c]) <= 3;
            if (!smooth) continue;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(std::lround(255 * srgb_encode(aces(l[c]))), t[c], 1) << x << "," << y;
            ++compared;
        }
    EXPECT_GT(compared, 200u);
}

TEST(Demo, WritesTheVolumeAndImages) {
    const fs::path dir = scratch_dir("demo");
    // Small images keep it quick; the mesh is the default marble-driven one the demo uses.
    const auto r = run_waxwork("demo -o " + dir.string() + " --width 96 --height 72 --no-editor");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir / "spot.vtu"));
    size_t images = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (entry.path().extension() != ".png") continue;
        ++images;
        const Image png = read_png(entry.path());
        EXPECT_EQ(png.width, 96);
        EXPECT_EQ(png.height, 72);
        EXPECT_NE(r.out.find(entry.path().string()), std::string::npos) << "not reported: " << entry.path();
    }
    EXPECT_GE(images, 4u);
}

}  // namespace
}  // namespace waxwork
