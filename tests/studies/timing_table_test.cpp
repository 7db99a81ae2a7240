// The Table 1 measurement (bench/studies/timing_table.h) on a small mesh: every stage runs and is timed.
#include "bench/studies/timing_table.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

TEST(TimingTable, MeasuresEveryStageOnASmallMesh) {
    TimingOptions options;
    options.target_tets = 60'000;
    const TimingRow row = measure_timing_row(WAXWORK_ASSET_DIR "/meshes/spot.obj", options);
    EXPECT_EQ(row.model, "spot");
    EXPECT_NEAR(static_cast<double>(row.tets), 60'000.0, 12'000.0);
    EXPECT_GE(row.levels, 2);
    for (double ms : {row.connectivity_ms, row.hierarchy_ms, row.matrix_ms, row.solve_ms, row.cut_ms, row.paint_ms})
        EXPECT_GT(ms, 0.0);
    EXPECT_DOUBLE_EQ(row.build_ms, row.connectivity_ms + row.hierarchy_ms);
    const std::string md = timing_table_markdown({row});
    EXPECT_NE(md.find("| spot | "), std::string::npos);
    EXPECT_NE(md.find("Bunny (paper, GTX 480) | 511019 | 3 | 72 | 26 | 49"), std::string::npos);
    EXPECT_EQ(to_json({row})[0]["Tb_ms"], row.build_ms);
}

}  // namespace
}  // namespace waxwork
