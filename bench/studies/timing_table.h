// The paper's Table 1 for Waxwork: per model at about 500K tets, the time to build
// the vertex neighbourhood and the multi-resolution hierarchy (T_b), to construct the diffusion matrix
// (T_m) and to solve it from zeros (T_s), plus a cut and a paint stroke with everything they rebuild.
// The paper measured a GTX 480 (T_b and T_s on the GPU, cutting on a 4-core CPU); these rows are this
// machine's CPU, and both are printed side by side.
#pragma once

#include "bench/studies/repeated_timing.h"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace waxwork {

struct PaperTimingRow {
    const char* model;
    size_t tets;
    int levels;
    double build_ms;   // T_b
    double matrix_ms;  // T_m
    double solve_ms;   // T_s
};

// TransCut Table 1 (GTX 480).
inline constexpr PaperTimingRow kTransCutTable1[] = {
    {"Bunny", 511019, 3, 72, 26, 49},      {"Tweety", 1011863, 4, 213, 67, 57}, {"Horse", 1020554, 4, 218, 65, 72},
    {"Feline", 1024674, 4, 219, 67, 121}, {"Gargoyle", 687724, 3, 166, 47, 49},
};

struct TimingRow {
    std::string model;
    std::string mesher;            // "tetgen", or "cgal" when TetGen cannot reach the tet count
    size_t tets = 0;
    size_t vertices = 0;
    int levels = 0;
    double meshing_ms = 0;
    double connectivity_ms = 0;
    double hierarchy_ms = 0;
    double build_ms = 0;           // T_b = connectivity + hierarchy
    double matrix_ms = 0;          // T_m: three channels and the source term
    double solve_ms = 0;           // T_s: the paper's multires scheme, rgb, from zeros to 1% estimated error
    std::array<int, 3> solve_level0_iterations{};  // T_s's level-0 CG iterations per channel, first run
    double cut_ms = 0;             // plane cut + 10 relaxation sweeps + connectivity, matrix and hierarchy
    double paint_ms = 0;           // 100-point stroke + matrix row updates + coarse level updates
    // The fastest and slowest run of each timed stage: "connectivity", "matrix", "hierarchy", "solve",
    // "paint", "cut" (the fields above are the medians).
    std::map<std::string, RunTimes> runs;
};

struct TimingOptions {
    std::string material = "marble";
    double mm_per_unit = 30;
    size_t target_tets = 500'000;
    int runs = 3;  // each stage's time is the median of this many runs
};

// Meshes `surface` with TetGen to about target_tets (with CGAL Mesh_3 when TetGen cannot: it keeps every
// input triangle, so a detailed surface such as the skull needs more tets) and times each stage
// options.runs times, keeping the median: single runs on this machine vary by 10-30%, and the first
// run of a stage in a process also maps every fresh page it touches (docs/performance.md),
// which would land on whichever model comes first. The cut runs on a fresh copy of the painted mesh
// each time (copying not timed). Throws what meshing and solving throw.
TimingRow measure_timing_row(const std::filesystem::path& surface, const TimingOptions& options);

nlohmann::ordered_json to_json(const std::vector<TimingRow>& rows);
// A markdown table: our rows (medians; T_m, T_s, cut and paint with their fastest and slowest run in
// brackets), then the paper's rows marked "(GTX 480)".
std::string timing_table_markdown(const std::vector<TimingRow>& rows);

}  // namespace waxwork
