// `--repair wrap`: the alpha-wrap repair from the command line, end to end.
#include "support/cli_run.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>

namespace waxwork {
namespace {

using namespace testing;
namespace fs = std::filesystem;

const std::string kShared = WAXWORK_SHARED_DIR;

TEST(WrapRepair, BadCowIsWrappedAndMeshedAsOneComponent) {
    const std::string cow = kShared + "/data/meshes/bad_cow.obj";
    if (!fs::exists(cow)) GTEST_SKIP() << "../shared is not present";
    const auto dir = scratch_dir("wrap_cow");
    const fs::path volume = dir / "cow.vtu";
    // The default size and mesher: the wrap, finer than the size, is remeshed for TetGen (kept as it
    // is, its offset slabs held TetGen's graded pass for minutes; CGAL split them into components).
    const auto r = run_waxwork("mesh " + cow + " --repair wrap -o " + volume.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("bad_cow.obj: repaired: wrapped (alpha "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("% of the diagonal)"), std::string::npos) << r.err;
    const auto summary = nlohmann::json::parse(r.out);
    ASSERT_TRUE(summary.contains("wrap")) << r.out;
    const auto& wrap = summary["wrap"];
    EXPECT_GT(double(wrap["alpha"]), 0.0);
    EXPECT_GT(double(wrap["offset"]), 0.0);
    EXPECT_GT(int(wrap["triangles"]), 0);
    EXPECT_GT(double(wrap["hausdorff"]), 0.0);
    EXPECT_GT(double(wrap["hausdorff_percent_of_diagonal"]), 0.0);
    EXPECT_LT(double(wrap["hausdorff_percent_of_diagonal"]), 5.0);  // the cow keeps its shape
    ASSERT_EQ(summary["repairs"].size(), 1u) << r.out;               // the wrap needs no other repair
    EXPECT_EQ(std::string(summary["repairs"][0]).rfind("wrapped (alpha ", 0), 0u) << r.out;
    EXPECT_EQ(summary["mesher"], "tetgen") << r.out;
    ASSERT_TRUE(summary.contains("surface_remeshed")) << r.out;
    EXPECT_LT(int(summary["surface_remeshed"]["triangles_out"]), int(wrap["triangles"])) << r.out;

    const auto i = run_waxwork("info " + volume.string());
    ASSERT_EQ(i.exit_code, 0) << i.err;
    const auto info = nlohmann::json::parse(i.out);
    EXPECT_EQ(info["components"], 1) << i.out;
    EXPECT_GT(double(info["volume"]), 0.0) << i.out;
}

TEST(WrapRepair, ExplicitAlphaAndOffsetAreUsed) {
    const auto dir = scratch_dir("wrap_explicit");
    const auto r = run_waxwork("mesh " + kAssets + "/meshes/cube.obj --repair wrap --wrap-alpha 0.2 --wrap-offset 0.01 "
                               "--max-tets 3000 --mesher cgal -o " + (dir / "cube.vtu").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto summary = nlohmann::json::parse(r.out);
    EXPECT_EQ(double(summary["wrap"]["alpha"]), 0.2);
    EXPECT_EQ(double(summary["wrap"]["offset"]), 0.01);
    EXPECT_NE(r.err.find("repaired: wrapped (alpha 0.2, offset 0.01): "), std::string::npos) << r.err;
}

TEST(WrapRepair, BadValuesAreOneLineErrorsNamingTheOption) {
    const auto dir = scratch_dir("wrap_bad");
    const std::string in = kAssets + "/meshes/cube.obj -o " + (dir / "x.vtu").string();
    struct Case {
        std::string args, expected;
    };
    for (const Case& c : {Case{" --repair wrap --wrap-alpha=-1", "--wrap-alpha: must be a positive length"},
                          Case{" --repair wrap --wrap-alpha 0", "--wrap-alpha: must be a positive length"},
                          Case{" --repair wrap --wrap-alpha nan", "--wrap-alpha: must be a positive length"},
                          Case{" --repair wrap --wrap-offset 0", "--wrap-offset: must be a positive length"},
                          Case{" --repair wrap --wrap-offset inf", "--wrap-offset"},
                          // Far below 1/2000 of the cube's diagonal: refused before any work.
                          Case{" --repair wrap --wrap-alpha 1e-6", "--wrap-alpha: 1e-06 is below 0.0005 of the model's diagonal"},
                          Case{" --repair glue", "--repair"},
                          Case{" --wrap-alpha 0.1", "--wrap-alpha"},              // needs --repair wrap
                          Case{" --repair wrap --fill-holes", "--repair"},        // one repair or the other
                          Case{" --repair wrap --autorefine", "--repair"}}) {
        const auto r = run_waxwork("mesh " + in + c.args);
        EXPECT_NE(r.exit_code, 0) << c.args;
        EXPECT_EQ(line_count(r.err), 1u) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.args << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(dir / "x.vtu"));
}

// Every command that meshes a surface takes the repair: `mesh`, `bench solvers` and `edit`.
TEST(WrapRepair, EveryMeshingCommandTakesIt) {
    for (const std::string command : {"mesh", "bench solvers", "edit"}) {
        const auto r = run_waxwork(command + " --help");
        EXPECT_EQ(r.exit_code, 0) << command;
        for (const std::string option : {"--repair", "--wrap-alpha", "--wrap-offset", "--fill-holes", "--autorefine",
                                         "--mesher", "--max-tets", "--edge"}) {
            if (command == "bench solvers" && option == "--edge") continue;  // it sizes by tet count only
            EXPECT_NE(r.out.find(option), std::string::npos) << command << " " << option;
        }
    }
}

}  // namespace
}  // namespace waxwork
