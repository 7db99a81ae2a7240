#include "base/error.h"
#include "tetops/model_scale.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace waxwork {
namespace {

TEST(ModelScale, DefaultPutsTheDiagonalNearHandSizeWithARoundNumber) {
    // Spot's bounding-box diagonal is 2.59 units: 30 mm per unit, the demo's scale.
    EXPECT_EQ(default_mm_per_unit(2.59), 30.0);
    for (double diagonal = 1e-4; diagonal < 1e7; diagonal *= 1.37) {  // inside the clamp (7.5e-5, 7.5e7)
        const double scale = default_mm_per_unit(diagonal);
        const double millimetres = scale * diagonal;
        EXPECT_GE(millimetres, 75.0 / 1.23) << diagonal;
        EXPECT_LE(millimetres, 75.0 * 1.23) << diagonal;
        // One of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten.
        const double mantissa = scale / std::pow(10.0, std::floor(std::log10(scale) + 1e-12));
        bool round = false;
        for (double m : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0}) round = round || std::abs(mantissa - m) < 1e-9;
        EXPECT_TRUE(round) << scale;
    }
}

TEST(ModelScale, DefaultStaysInTheScalesRangeAndRefusesNoSize) {
    EXPECT_EQ(default_mm_per_unit(1e-300), kMaxMmPerUnit);
    EXPECT_EQ(default_mm_per_unit(std::numeric_limits<double>::denorm_min()), kMaxMmPerUnit);
    EXPECT_EQ(default_mm_per_unit(1e300), kMinMmPerUnit);
    for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()})
        EXPECT_THROW(default_mm_per_unit(bad), InvalidArgumentError) << bad;
}

TEST(ModelScale, GivenWinsOverStoredWhichWinsOverTheModelsSize) {
    const Eigen::Vector3d extent(1, 2, 2);  // diagonal 3: 25 mm per unit
    const ModelScale given = choose_model_scale(7.0, 9.0, extent);
    EXPECT_EQ(given.mm_per_unit, 7.0);
    EXPECT_EQ(given.source, ScaleSource::Given);
    const ModelScale stored = choose_model_scale(std::nullopt, 9.0, extent);
    EXPECT_EQ(stored.mm_per_unit, 9.0);
    EXPECT_EQ(stored.source, ScaleSource::Stored);
    const ModelScale model = choose_model_scale(std::nullopt, std::nullopt, extent);
    EXPECT_EQ(model.mm_per_unit, 25.0);
    EXPECT_EQ(model.source, ScaleSource::ModelSize);
    EXPECT_EQ(describe_model_scale(model, extent),
              "25 mm per model unit (chosen from the model's size; --scale sets it): the model is 25 x 50 x 50 mm");
    EXPECT_EQ(describe_model_scale(stored, extent), "9 mm per model unit (stored in the volume): the model is 9 x 18 x 18 mm");
}

TEST(ModelScale, ProblemsNameTheRange) {
    EXPECT_EQ(mm_per_unit_problem(30), "");
    EXPECT_EQ(mm_per_unit_problem(kMinMmPerUnit), "");
    EXPECT_EQ(mm_per_unit_problem(kMaxMmPerUnit), "");
    for (double bad : {0.0, -3.0, 2e6, std::nan(""), std::numeric_limits<double>::infinity()})
        EXPECT_NE(mm_per_unit_problem(bad).find("between 1e-6 and 1e6"), std::string::npos) << bad;
}

TEST(ModelScale, BoundingExtent) {
    EXPECT_EQ(bounding_extent({}), Eigen::Vector3d::Zero());
    EXPECT_EQ(bounding_extent({{1, 2, 3}, {-1, 5, 3}, {0, 0, 4}}), Eigen::Vector3d(2, 5, 1));
}

}  // namespace
}  // namespace waxwork
