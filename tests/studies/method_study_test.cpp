// The seeds' methods beside TransCut (bench/studies/method_study.h) on the quick ball sizes.
#include "bench/studies/method_study.h"

#include <gtest/gtest.h>

#include <cmath>

namespace waxwork {
namespace {

const MethodSeries* find_series(const std::vector<MethodSeries>& all, const std::string& scene,
                                const std::string& method) {
    for (const MethodSeries& s : all)
        if (s.scene == scene && s.method == method) return &s;
    return nullptr;
}

TEST(MethodStudy, EveryMethodRunsOnTheBallAndTheVolumeMethodsConverge) {
    MethodStudyOptions options;
    options.quick = true;
    const std::vector<MethodSeries> all = study_methods(options);
    for (const std::string scene : {"ball uniform", "ball directional"}) {
        for (const std::string method : {"transcut_cg", "transcut_multigrid_cg", "fd", "fd-cg", "fvm", "fvm-cg", "lbm",
                                         "dipole"}) {
            const MethodSeries* s = find_series(all, scene, method);
            ASSERT_NE(s, nullptr) << scene << " " << method;
            ASSERT_EQ(s->runs.size(), 3u) << scene << " " << method;
            for (const MethodRun& run : s->runs) {
                EXPECT_TRUE(std::isfinite(run.relative_error)) << scene << " " << method;
                EXPECT_GT(run.unknowns, 0u) << scene << " " << method;
                EXPECT_GT(run.setup_ms + run.solve_ms, 0.0) << scene << " " << method;
            }
            // Every volume method converges; the dipole is a half-space model and need not.
            if (method != "dipole") {
                EXPECT_LT(s->runs.back().relative_error, s->runs.front().relative_error) << scene << " " << method;
                EXPECT_GT(s->fit_order().order, 0.5) << scene << " " << method;
            }
        }
        // The same system, two solvers: the same error.
        EXPECT_NEAR(find_series(all, scene, "fd")->runs.back().relative_error,
                    find_series(all, scene, "fd-cg")->runs.back().relative_error, 1e-3);
        EXPECT_NEAR(find_series(all, scene, "fvm")->runs.back().relative_error,
                    find_series(all, scene, "fvm-cg")->runs.back().relative_error, 1e-3);
        EXPECT_NEAR(find_series(all, scene, "transcut_cg")->runs.back().relative_error,
                    find_series(all, scene, "transcut_multigrid_cg")->runs.back().relative_error, 1e-4);
    }
    const nlohmann::ordered_json json = to_json(all);
    ASSERT_FALSE(json.empty());
    EXPECT_TRUE(json[0].contains("observed_order"));
    EXPECT_EQ(json[0]["runs"].size(), 3u);
    EXPECT_NE(method_table_markdown(all).find("| ball directional | lbm |"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
