// `mpirun -n N waxwork render ... --engine petsc` end to end: the distributed solve against the CPU
// engine's, and bad input under MPI failing once and cleanly. Built only when CMake found PETSc and
// mpirun (WAXWORK_MPIRUN); every run is bounded by `timeout` so that a hang fails instead of blocking.
#include "io/image_io.h"
#include "support/cli_run.h"
#include "support/fields_table.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

#ifdef WAXWORK_MPIRUN

// Open MPI refuses root without --allow-run-as-root; --oversubscribe lets 2 ranks share 1 core.
std::string mpirun(int processes) {
    return "timeout 60 " + std::string(WAXWORK_MPIRUN) + " --allow-run-as-root --oversubscribe -n " +
           std::to_string(processes) + " ";
}

size_t occurrences(const std::string& text, const std::string& what) {
    size_t count = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
    return count;
}

// The largest difference of any channel of any pixel between two images of the same size.
int largest_pixel_difference(const fs::path& a_path, const fs::path& b_path) {
    const Image a = read_png(a_path), b = read_png(b_path);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    if (a.width != b.width || a.height != b.height) return 255;
    int largest = 0;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 4; ++c) largest = std::max(largest, std::abs(int(a.pixel(x, y)[c]) - int(b.pixel(x, y)[c])));
    return largest;
}

class MpiRender : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = scratch_dir("mpi_render");
        volume_ = dir_ / "cube.vtu";
        const auto m = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + volume_.string() + " --max-tets 3000");
        ASSERT_EQ(m.exit_code, 0) << m.err;
        // The serial reference, solved well below the comparison's tolerance.
        const auto r = run_waxwork(render_arguments("serial") + " --tol 1e-7");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        serial_ = read_fields(dir_ / "serial.csv");
    }
    static std::string render_arguments(const std::string& name) {
        return "render " + volume_.string() + " -o " + (dir_ / (name + ".png")).string() + " --fields " +
               (dir_ / (name + ".csv")).string() + " --material marble --light dir:-1,-0.5,-0.2 --scale 10 --width 96 --height 72";
    }
    // The largest difference of phi from the serial solve's, relative to the largest serial phi.
    static double phi_difference(const Fields& f) {
        double largest = 0, difference = 0;
        EXPECT_EQ(f.rows.size(), serial_.rows.size());
        for (size_t v = 0; v < std::min(f.rows.size(), serial_.rows.size()); ++v)
            for (int c = 0; c < 3; ++c) {
                largest = std::max(largest, std::abs(serial_.rows[v].phi[c]));
                difference = std::max(difference, std::abs(f.rows[v].phi[c] - serial_.rows[v].phi[c]));
            }
        return difference / largest;
    }
    static fs::path dir_, volume_;
    static Fields serial_;
};
fs::path MpiRender::dir_, MpiRender::volume_;
Fields MpiRender::serial_;

TEST_F(MpiRender, OneAndTwoProcessesMatchTheSerialSolve) {
    for (const int processes : {1, 2}) {
        const std::string name = "petsc" + std::to_string(processes);
        const auto r = run_waxwork(render_arguments(name) + " --engine petsc --tol 1e-6", mpirun(processes));
        ASSERT_EQ(r.exit_code, 0) << r.err;
        ASSERT_EQ(line_count(r.out), 1u) << "one summary, from rank 0: " << r.out;
        const auto summary = nlohmann::json::parse(r.out);
        EXPECT_EQ(summary["engine"], "petsc");
        const auto& petsc = summary["petsc"];
        EXPECT_EQ(petsc["processes"], processes);
        EXPECT_EQ(petsc["preconditioner"], "boomeramg");
        const auto rows = petsc["rows_per_process"].get<std::vector<int64_t>>();
        ASSERT_EQ(rows.size(), static_cast<size_t>(processes));
        int64_t total = 0;
        for (const int64_t n : rows) total += n;
        EXPECT_EQ(total, summary["vertices"].get<int64_t>());
        EXPECT_LE(std::abs(rows.front() - rows.back()), 1) << "balanced by vertex count";
        EXPECT_GT(petsc["edges"].get<int64_t>(), summary["vertices"].get<int64_t>());
        if (processes == 1) {
            EXPECT_EQ(petsc["edge_cut"], 0);
        } else {
            // A Morton range split of a cube cuts it along a plane: some edges, a small share of all.
            EXPECT_GT(petsc["edge_cut"].get<int64_t>(), 0);
            EXPECT_LT(petsc["edge_cut"].get<int64_t>(), petsc["edges"].get<int64_t>() / 5);
        }
        EXPECT_EQ(petsc["peak_rss_mib_per_process"].size(), static_cast<size_t>(processes));

        const Fields f = read_fields(dir_ / (name + ".csv"));
        EXPECT_LT(phi_difference(f), 1e-4) << processes << " processes";
        EXPECT_LE(largest_pixel_difference(dir_ / "serial.png", dir_ / (name + ".png")), 1)
            << "pixels of the " << processes << "-process image against the serial one";
    }
}

TEST_F(MpiRender, GamgAtTheDefaultToleranceStaysWithinIt) {
    const auto r = run_waxwork(render_arguments("gamg") + " --engine petsc --pc gamg", mpirun(2));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["petsc"]["preconditioner"], "gamg");
    EXPECT_LT(phi_difference(read_fields(dir_ / "gamg.csv")), 1e-2);
}

TEST_F(MpiRender, AFileMissingOnOneProcessFailsEveryProcessWithOneMessage) {
    // Two programs in one MPI job (mpirun's MPMD form): rank 1 is given a file that does not exist.
    const fs::path missing = dir_ / "missing.vtu";
    const std::string good = render_arguments("never") + " --engine petsc";
    std::string bad = good;
    bad.replace(bad.find(volume_.string()), volume_.string().size(), missing.string());
    const std::string launcher = "timeout 60 " + std::string(WAXWORK_MPIRUN) + " --allow-run-as-root --oversubscribe -n 1 " +
                                 std::string(WAXWORK_BINARY) + " " + good + " : -n 1 ";
    const auto r = run_waxwork(bad, launcher);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.exit_code, 124) << "timed out: a process hung";
    EXPECT_EQ(occurrences(r.err, "waxwork: "), 1u) << r.err;
    EXPECT_NE(r.err.find(missing.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(process 1 of 2)"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(dir_ / "never.png"));
}

TEST_F(MpiRender, MoreProcessesThanVerticesFailWithOneMessage) {
    // One tet: four vertices, for five processes.
    const fs::path node = dir_ / "tet.node", ele = dir_ / "tet.ele";
    std::ofstream(node) << "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";
    std::ofstream(ele) << "1 4 0\n0 0 1 2 3\n";
    const auto r = run_waxwork("render " + node.string() + " -o " + (dir_ / "tet.png").string() + " --engine petsc",
                               mpirun(5));
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.exit_code, 124) << "timed out: a process hung";
    EXPECT_EQ(occurrences(r.err, "waxwork: "), 1u) << r.err;
    EXPECT_NE(r.err.find("5 processes for 4 vertices"), std::string::npos) << r.err;
}

TEST_F(MpiRender, ABadOptionFailsWithOneMessage) {
    const auto r = run_waxwork(render_arguments("bad") + " --engine petsc --pc jacobi", mpirun(2));
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(occurrences(r.err, "waxwork: "), 1u) << r.err;
    EXPECT_NE(r.err.find("--pc"), std::string::npos) << r.err;
}

TEST_F(MpiRender, ASessionOfRendersAndSavesMatchesTheCpuReplay) {
    const fs::path session = dir_ / "session.json";
    std::ofstream(session) << R"({"input": {"volume": ")" << volume_.string() << R"("}, "material": "skin1",
        "image": {"width": 96, "height": 72}, "tolerance": 1e-6, "steps": [{"render": "a.png"},
        {"light": {"lights": [{"direction": [1, -0.3, -0.5]}]}}, {"camera": {"eye_direction": [1, 0.5, 1]}},
        {"render": "b.png"}, {"save": "c.vtu"}]})";
    const auto cpu = run_waxwork("run " + session.string() + " -o " + (dir_ / "session_cpu").string());
    ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
    const auto petsc = run_waxwork("run " + session.string() + " -o " + (dir_ / "session_petsc").string() + " --engine petsc",
                                   mpirun(2));
    ASSERT_EQ(petsc.exit_code, 0) << petsc.err;
    EXPECT_NE(petsc.out.find("on each of 2 processes"), std::string::npos) << petsc.out;
    for (const char* image : {"a.png", "b.png"})
        EXPECT_LE(largest_pixel_difference(dir_ / "session_cpu" / image, dir_ / "session_petsc" / image), 1) << image;
    EXPECT_EQ(read_text(dir_ / "session_cpu" / "c.vtu"), read_text(dir_ / "session_petsc" / "c.vtu"));
}

TEST_F(MpiRender, ASessionWithAnEditIsRefusedOnce) {
    const fs::path session = dir_ / "edit_session.json";
    std::ofstream(session) << R"({"input": {"volume": ")" << volume_.string() << R"("}, "steps": [
        {"op": "plane_cut", "normal": [1, 0, 0], "offset": 0}, {"render": "a.png"}]})";
    const auto r = run_waxwork("run " + session.string() + " -o " + (dir_ / "edit_session").string() + " --engine petsc",
                               mpirun(2));
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.exit_code, 124) << "timed out: a process hung";
    EXPECT_EQ(occurrences(r.err, "waxwork: "), 1u) << r.err;
    EXPECT_NE(r.err.find("step 0: --engine petsc replays converged renders"), std::string::npos) << r.err;
}

#endif  // WAXWORK_MPIRUN

TEST(RenderEngine, PcWithoutThePetscEngineIsRefused) {
    const auto r = run_waxwork("render " + kAssets + "/missing.vtu -o out.png --pc gamg");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("--pc applies only with --engine petsc"), std::string::npos) << r.err;
}

#ifndef WAXWORK_HAVE_PETSC
TEST(RenderEngine, ThePetscEngineNeedsAPetscBuild) {
    const auto r = run_waxwork("render " + kAssets + "/missing.vtu -o out.png --engine petsc");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("this build has no PETSc"), std::string::npos) << r.err;
}
#endif

}  // namespace
}  // namespace waxwork
