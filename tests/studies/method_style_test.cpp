// method_style (bench/studies/method_style.h): one colour per method, none repeated, every solver of the
// comparison styled.
#include "bench/studies/method_style.h"

#include <gtest/gtest.h>

#include <set>

namespace waxwork {
namespace {

TEST(MethodStyle, EveryMethodHasItsOwnColourAndLabel) {
    std::set<std::string> colours, labels, keys;
    for (const MethodStyle& style : method_styles()) {
        EXPECT_TRUE(colours.insert(style.colour).second) << style.key << " repeats " << style.colour;
        EXPECT_TRUE(labels.insert(style.label).second) << style.key;
        EXPECT_TRUE(keys.insert(style.key).second) << style.key;
        EXPECT_EQ(style.colour.size(), 7u) << style.key;
    }
    EXPECT_GT(colours.size(), 8u);
    for (const char* key : {"jacobi_cg", "jacobi_cg_double", "multires", "multigrid_cg", "cascadic_cg", "multigrid_cg_rgb",
                            "eigen_ic_cg", "petsc_cg_gamg", "petsc_cg_boomeramg", "gpu_cg", "gpu_multires", "gpu_multigrid_cg",
                            "direct"})
        EXPECT_NE(find_method_style(key), nullptr) << key;
    EXPECT_EQ(find_method_style("no_such_solver"), nullptr);
    EXPECT_EQ(find_method_style("jacobi_cg")->label, "Jacobi CG (float)");
    EXPECT_EQ(find_method_style("direct")->label, "CHOLMOD direct");
}

TEST(MethodStyle, PaletteColoursAreDistinct) {
    const std::vector<std::string>& palette = chart_palette();
    EXPECT_EQ(std::set<std::string>(palette.begin(), palette.end()).size(), palette.size());
    EXPECT_GT(palette.size(), 8u);
}

}  // namespace
}  // namespace waxwork
