// The Table 1 measurement (bench/studies/timing_table.h) on a small mesh: every stage runs and is timed.
#include "bench/studies/timing_table.h"

#include <gtest/gtest.h>

#include <cstdio>

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
    // Every stage's median lies within its fastest and slowest run, which the JSON and the table carry.
    const std::pair<const char*, double> stages[] = {{"connectivity", row.connectivity_ms}, {"matrix", row.matrix_ms},
                                                     {"hierarchy", row.hierarchy_ms},       {"solve", row.solve_ms},
                                                     {"paint", row.paint_ms},               {"cut", row.cut_ms}};
    const auto runs = to_json({row})[0]["runs_ms"];
    ASSERT_EQ(runs.size(), 6u);
    for (const auto& [stage, median] : stages) {
        ASSERT_TRUE(row.runs.count(stage)) << stage;
        const RunTimes& t = row.runs.at(stage);
        EXPECT_EQ(t.ms, median) << stage;
        EXPECT_LE(t.min_ms, t.ms) << stage;
        EXPECT_GE(t.max_ms, t.ms) << stage;
        EXPECT_EQ(runs[stage]["min"], t.min_ms) << stage;
        EXPECT_EQ(runs[stage]["max"], t.max_ms) << stage;
    }
    char solve[64];
    std::snprintf(solve, sizeof solve, "| %.0f (%.0f-%.0f) |", row.solve_ms, row.runs.at("solve").min_ms,
                  row.runs.at("solve").max_ms);
    if (row.runs.at("solve").min_ms != row.runs.at("solve").max_ms) {
        EXPECT_NE(md.find(solve), std::string::npos) << md;
    }
}

}  // namespace
}  // namespace waxwork
