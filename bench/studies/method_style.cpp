#include "bench/studies/method_style.h"

namespace waxwork {

const std::vector<MethodStyle>& method_styles() {
    static const std::vector<MethodStyle> styles = {
        {"jacobi_cg", "Jacobi CG (float)", "#0072B2", Marker::Circle, false},
        {"jacobi_cg_double", "Jacobi CG (double)", "#56B4E9", Marker::Square, false},
        {"multires", "Multires (paper)", "#D55E00", Marker::TriangleUp, false},
        {"multigrid_cg", "Multigrid CG", "#009E73", Marker::Diamond, false},
        {"cascadic_cg", "Cascadic CG", "#E69F00", Marker::TriangleDown, false},
        {"multigrid_cg_rgb", "Multigrid CG (RGB frame solver)", "#CC79A7", Marker::Square, false},
        {"eigen_ic_cg", "Eigen IC-CG", "#000000", Marker::Cross, false},
        {"petsc_cg_gamg", "PETSc CG + GAMG", "#AA4499", Marker::TriangleDown, false},
        {"petsc_cg_boomeramg", "PETSc CG + hypre BoomerAMG", "#332288", Marker::TriangleUp, false},
        {"gpu_cg", "GPU Jacobi CG", "#882255", Marker::Circle, true},
        {"gpu_multires", "GPU multires", "#44AA99", Marker::TriangleUp, true},
        {"gpu_multigrid_cg", "GPU multigrid CG", "#117733", Marker::Diamond, true},
        {"direct", "CHOLMOD direct", "#999933", Marker::Plus, false},
    };
    return styles;
}

const MethodStyle* find_method_style(const std::string& key) {
    for (const MethodStyle& style : method_styles())
        if (style.key == key) return &style;
    return nullptr;
}

const std::vector<std::string>& chart_palette() {
    static const std::vector<std::string> palette = {
        "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000",
        "#882255", "#44AA99", "#117733", "#999933", "#AA4499", "#332288", "#DDCC77", "#888888"};
    return palette;
}

}  // namespace waxwork
