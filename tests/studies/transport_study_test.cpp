// The diffusion-against-transport study's code path on a tiny setting: every case runs and reports
// finite, consistent numbers.
#include "bench/studies/transport_study.h"

#include <gtest/gtest.h>

#include <cmath>

namespace waxwork {
namespace {

TEST(TransportStudy, EveryCaseReportsAnImageComparison) {
    TransportStudyOptions options;
    options.materials = {"skin1"};
    options.cube_scales = {3};
    options.plate_thicknesses = {2};
    options.width = 16;
    options.height = 12;
    options.cube_cells = 3;
    options.mc_seconds = 0.2;
    const std::vector<TransportCase> cases = run_transport_study(options);
    ASSERT_EQ(cases.size(), 4u);  // a cube, a plate from both sides, the cut cube
    EXPECT_EQ(cases[0].shape, "cube");
    EXPECT_EQ(cases[1].shape, "plate, lit side");
    EXPECT_EQ(cases[2].shape, "plate, far side");
    EXPECT_EQ(cases[3].shape, "cut cube");
    EXPECT_NEAR(cases[1].size_mfp, 2.0, 1e-12);
    // skin1's green: mu_s' = 0.88, mu_a = 0.17 per mm.
    EXPECT_NEAR(cases[0].albedo, 0.88 / 1.05, 1e-12);
    EXPECT_NEAR(cases[0].size_mfp, 3 * 1.05, 1e-12);
    for (const TransportCase& c : cases) {
        EXPECT_GT(c.difference.pixels, 0) << c.shape;
        EXPECT_TRUE(std::isfinite(c.difference.relative_l2)) << c.shape;
        EXPECT_GE(c.difference.relative_l2, c.difference.scaled_relative_l2) << c.shape;
        EXPECT_LE(model_error(c), c.difference.scaled_relative_l2) << c.shape;
        EXPECT_GT(c.difference.scale, 0) << c.shape;
        EXPECT_GT(c.mc_paths, 0) << c.shape;
        EXPECT_FALSE(c.convergence.empty()) << c.shape;
        EXPECT_GT(c.live_ms, 0) << c.shape;
    }
    const std::string table = transport_table_markdown(cases);
    EXPECT_NE(table.find("| cut cube | skin1 |"), std::string::npos);
}

}  // namespace
}  // namespace waxwork
