// Error against mesh size (bench/studies/accuracy_study.h) on the quick sizes.
#include "bench/studies/accuracy_study.h"

#include <gtest/gtest.h>

namespace waxwork {
namespace {

TEST(AccuracyStudy, BallErrorFallsAtAboutSecondOrder) {
    const std::vector<ConvergenceSeries> series = study_ball_convergence({.quick = true});
    ASSERT_EQ(series.size(), 4u);
    for (const ConvergenceSeries& s : series) {
        ASSERT_EQ(s.points.size(), 3u) << s.name;
        EXPECT_LT(s.points.back().relative_error, s.points.front().relative_error) << s.name;
        EXPECT_LT(s.points.back().relative_error, 0.02) << s.name;
        EXPECT_GT(s.observed_order(), 1.0) << s.name;  // linear elements: ~2 in L2
    }
    EXPECT_EQ(to_json(series)[0]["points"].size(), 3u);
}

TEST(AccuracyStudy, SurfaceMeshesConvergeToTheirFineReference) {
    SurfaceConvergenceOptions options;
    options.surface = WAXWORK_ASSET_DIR "/meshes/spot.obj";
    options.mm_per_unit = 3;  // coarse default mesh: fast
    options.size_factors = {2.0, 1.0};
    options.reference_size_factor = 0.7;
    const ConvergenceSeries series = study_surface_convergence(options);
    ASSERT_EQ(series.points.size(), 2u);
    EXPECT_LT(series.points[0].tets, series.points[1].tets);
    EXPECT_LT(series.points[1].relative_error, series.points[0].relative_error);
    EXPECT_GT(series.points[1].relative_error, 0.0);
}

TEST(ConvergenceSeries, ObservedOrderIsTheLogLogSlope) {
    ConvergenceSeries s;
    for (double h : {1.0, 0.5, 0.25}) s.points.push_back({100, h, 0.3 * h * h, 0});
    EXPECT_NEAR(s.observed_order(), 2.0, 1e-12);
}

}  // namespace
}  // namespace waxwork
