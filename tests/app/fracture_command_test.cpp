// `waxwork cut` and `waxwork fracture` end to end: a meshed cube in, a valid volume and a
// one-line JSON summary out; bad input gives a one-line error and writes nothing.
#include "io/volume_file.h"
#include "support/cli_run.h"
#include "tetops/connectivity.h"
#include "tetops/quality.h"
#include "tetops/test_meshes.h"
#include "tetops/tet_mesh.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

// The embedded cube meshed once per test into `dir`.
fs::path meshed_cube(const fs::path& dir) {
    const auto volume = dir / "cube.vtu";
    const auto r = run_waxwork("mesh " + kAssets + "/meshes/cube.obj -o " + volume.string() + " --max-tets 3000");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return volume;
}

// Tets of `mesh` under min(0.5 degrees, the angle of the tet of `before` with the same original id):
// the exceptions to the guarantee of exact cuts and fractures, recounted from the written files.
size_t tets_under_guard(const TetMesh& mesh, const TetMesh& before) {
    std::map<int64_t, size_t> index;
    for (size_t t = 0; t < before.tet_count(); ++t) index[before.original_ids[t]] = t;
    EXPECT_EQ(index.size(), before.tet_count()) << "original ids are not unique";
    const std::vector<double> after_deg = min_dihedral_angles_deg(mesh), before_deg = min_dihedral_angles_deg(before);
    size_t count = 0;
    for (size_t t = 0; t < mesh.tet_count(); ++t)
        if (after_deg[t] < std::min(0.5, before_deg[index.at(mesh.original_ids[t])])) ++count;
    return count;
}

TEST(FractureCommand, BreaksIntoPiecesAndSummarises) {
    const auto dir = scratch_dir("fracture_cli");
    const auto in = meshed_cube(dir);
    const TetMesh before = read_volume(in.string());
    for (const std::string mode : {"--exact", "--no-exact"}) {
        const auto out = dir / "pieces.vtu";
        const auto r = run_waxwork("fracture " + in.string() + " -o " + out.string() + " --pieces 5 --seed 3 " + mode);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        ASSERT_EQ(line_count(r.out), 1u) << r.out;
        const auto summary = nlohmann::json::parse(r.out);
        for (const char* key : {"tets_before", "vertices_before", "tets_after", "vertices_after", "pieces",
                                "min_dihedral_deg", "tets_under_guard", "vertices_collapsed", "milliseconds"})
            EXPECT_TRUE(summary.contains(key)) << key;
        EXPECT_EQ(summary["tets_before"], before.tet_count());
        const TetMesh mesh = read_volume(out.string());
        EXPECT_EQ(size_t(summary["tets_under_guard"]), tets_under_guard(mesh, before)) << mode;
        EXPECT_NO_THROW(validate(mesh));
        EXPECT_EQ(summary["tets_after"], mesh.tet_count());
        EXPECT_EQ(summary["vertices_after"], mesh.vertex_count());
        EXPECT_EQ(summary["pieces"], mesh.piece_transforms.size());
        EXPECT_GE(int(summary["pieces"]), 2);
        EXPECT_LE(int(summary["pieces"]), 5);
        EXPECT_GT(double(summary["min_dihedral_deg"]), 0.0);
        EXPECT_NEAR(total_volume(mesh), total_volume(before), 1e-9 * total_volume(before));
        // The pieces are apart: as many components as pieces.
        EXPECT_EQ(build_connectivity(mesh).component_count, int(summary["pieces"])) << mode;
        if (mode == "--no-exact") {
            EXPECT_EQ(mesh.tet_count(), before.tet_count());
            EXPECT_EQ(summary["vertices_collapsed"], 0);  // nothing split, nothing to collapse
        }
    }
    // --no-collapse keeps every split the walls made; the default collapses what swallowed walls left.
    const auto kept = dir / "kept.vtu", collapsed = dir / "collapsed.vtu";
    const auto k = run_waxwork("fracture " + in.string() + " -o " + kept.string() + " --pieces 12 --seed 3 --no-collapse");
    const auto c = run_waxwork("fracture " + in.string() + " -o " + collapsed.string() + " --pieces 12 --seed 3");
    ASSERT_EQ(k.exit_code, 0) << k.err;
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const auto kept_summary = nlohmann::json::parse(k.out), collapsed_summary = nlohmann::json::parse(c.out);
    EXPECT_EQ(kept_summary["vertices_collapsed"], 0);
    EXPECT_GT(int(collapsed_summary["vertices_collapsed"]), 0);
    EXPECT_LT(read_volume(collapsed.string()).tet_count(), read_volume(kept.string()).tet_count());
    EXPECT_EQ(kept_summary["pieces"], collapsed_summary["pieces"]);
    EXPECT_GE(double(collapsed_summary["min_dihedral_deg"]), double(kept_summary["min_dihedral_deg"]));

    // The same seed gives the same file.
    const auto a = dir / "a.vtu", b = dir / "b.vtu";
    ASSERT_EQ(run_waxwork("fracture " + in.string() + " -o " + a.string() + " --pieces 4 --seed 9").exit_code, 0);
    ASSERT_EQ(run_waxwork("fracture " + in.string() + " -o " + b.string() + " --pieces 4 --seed 9").exit_code, 0);
    EXPECT_EQ(read_volume(a.string()), read_volume(b.string()));
}

TEST(FractureCommand, BadInputIsAOneLineError) {
    const auto dir = scratch_dir("fracture_cli_bad");
    const auto in = meshed_cube(dir);
    const auto out = dir / "never.vtu";
    for (const std::string& args : std::vector<std::string>{
             in.string() + " -o " + out.string() + " --pieces 0", in.string() + " -o " + out.string() + " --pieces -4",
          in.string() + " -o " + out.string() + " --pieces 100000000",
          (dir / "missing.vtu").string() + " -o " + out.string() + " --pieces 3",
          in.string() + " -o " + out.string() + " --pieces x", in.string() + " -o " + out.string()}) {
        const auto r = run_waxwork("fracture " + args);
        EXPECT_NE(r.exit_code, 0) << args;
        EXPECT_EQ(line_count(r.err), 1u) << args << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(out));
}

TEST(CutCommand, ExactCutLeavesTheCrossSectionOnThePlane) {
    const auto dir = scratch_dir("cut_exact_cli");
    const auto in = meshed_cube(dir);
    const TetMesh before = read_volume(in.string());
    const auto box = bounding_box(before);
    const double mid = 0.5 * (box[0].x() + box[1].x()) + 0.0123;
    const auto out = dir / "cut.vtu";
    const auto r = run_waxwork("cut " + in.string() + " -o " + out.string() + " --plane=1,0,0," + std::to_string(mid) +
                               " --exact");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(line_count(r.out), 1u);
    const auto summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(summary["mode"], "exact");
    EXPECT_GT(int(summary["tets_split"]), 0);
    const TetMesh mesh = read_volume(out.string());
    ASSERT_TRUE(summary.contains("tets_under_guard"));
    EXPECT_EQ(size_t(summary["tets_under_guard"]), tets_under_guard(mesh, before));
    EXPECT_NO_THROW(validate(mesh));
    EXPECT_EQ(summary["tets_after"], mesh.tet_count());
    const double mid_written = std::stod(std::to_string(mid));
    double max_x = -1e300;
    for (const auto& p : mesh.positions) max_x = std::max(max_x, p.x());
    EXPECT_NEAR(max_x, mid_written, 1e-12);
    // The cube is a box: the kept volume is exact.
    const Eigen::Vector3d extent = box[1] - box[0];
    EXPECT_NEAR(total_volume(mesh), (mid_written - box[0].x()) * extent.y() * extent.z(), 1e-9);
    const auto bad = run_waxwork("cut " + in.string() + " -o " + (dir / "x.vtu").string() + " --plane=0,0,0,1 --exact");
    EXPECT_NE(bad.exit_code, 0);
    EXPECT_EQ(line_count(bad.err), 1u);
    EXPECT_NE(bad.err.find("cut --plane=0,0,0,1: the normal must not be the zero vector"), std::string::npos) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "x.vtu"));
}

TEST(CutCommand, ACutThatLeavesNothingIsAnErrorAndWritesNothing) {
    const auto dir = scratch_dir("cut_everything_cli");
    const auto in = meshed_cube(dir);
    const auto out = dir / "never.vtu";
    for (const std::string mode : {"", " --exact"}) {
        const auto r = run_waxwork("cut " + in.string() + " -o " + out.string() + " --plane=1,0,0,-100" + mode);
        EXPECT_NE(r.exit_code, 0) << mode;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("nothing would be left"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("waxwork: " + in.string() + ": "), std::string::npos) << r.err;  // names the volume
        EXPECT_FALSE(fs::exists(out)) << mode;
    }
}

TEST(CutCommand, RemoveFragmentsDropsTheShortArmACutLeavesOfAU) {
    const auto dir = scratch_dir("cut_fragments_cli");
    // A U of 7 x 6 x 2 cells: a bridge along y in [0, 1], a long arm at x in [0, 1] up to y = 6 and a
    // short one at x in [6, 7] up to y = 2. Cutting the bridge away (y < 1.5) leaves the arms apart.
    const auto in = dir / "u.vtu";
    write_volume(testing::make_cell_mesh(7, 6, 2, [](int i, int j, int) { return j == 0 || i == 0 || (i == 6 && j <= 1); }),
                 in);
    const auto out = dir / "cut.vtu";
    const std::string cut = "cut " + in.string() + " -o " + out.string() + " --plane=0,-1,0,-1.5";
    for (const std::string mode : {"", " --exact"}) {
        SCOPED_TRACE(mode);
        const auto kept = run_waxwork(cut + mode);
        ASSERT_EQ(kept.exit_code, 0) << kept.err;
        EXPECT_EQ(nlohmann::json::parse(kept.out)["components"], 2);
        EXPECT_FALSE(nlohmann::json::parse(kept.out).contains("fragments_removed"));

        const auto r = run_waxwork(cut + mode + " --remove-fragments 0.2");
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const auto summary = nlohmann::json::parse(r.out);
        EXPECT_EQ(summary["fragments_removed"], 1);
        EXPECT_EQ(summary["components"], 1);
        const TetMesh mesh = read_volume(out.string());
        EXPECT_EQ(summary["tets_after"], mesh.tet_count());
        // Whole cells: the short arm's 12 tets go (an exact cut leaves half a cell of it, split).
        if (mode.empty()) {
            EXPECT_EQ(summary["fragment_tets_removed"], 12);
        }
        EXPECT_EQ(mesh.tet_count() + size_t(summary["fragment_tets_removed"]),
                  size_t(nlohmann::json::parse(kept.out)["tets_after"]));
        for (const auto& p : mesh.positions) EXPECT_LE(p.x(), 1.0);
        EXPECT_EQ(build_connectivity(mesh).component_count, 1);
    }
    fs::remove(out);
    for (const std::string bad : {"1", "-0.5", "nan", "\"\"", "0.1x"}) {
        const auto r = run_waxwork(cut + " --remove-fragments " + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_EQ(line_count(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("--remove-fragments"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out)) << bad;
    }
}

}  // namespace
}  // namespace waxwork
