// The multi-resolution solver of multires/multires_solver.h (Li et al. 2013, Sec. 4) on the GPU: the
// hierarchy is built on the CPU (independent sets, Eq. 16 weights, Eq. 17 coarse matrices in double)
// and uploaded once in float; each solve restricts b by injection, runs BiCGSTAB on the coarsest
// level to convergence and a few iterations on each finer level (gpu_bicgstab.h), interpolates down
// (Eq. 16) and finishes with the level-0 Jacobi CG of solver/gpu/gpu_conjugate_gradient.h, all three
// channels at once and without leaving the device except for reduction scalars.
//
// Per-frame mode (solve_frame): only the level-0 CG, warm-started from the previous frame, as the CPU
// MultiresSolver does.
#pragma once

#include "multires/gpu_bicgstab.h"
#include "multires/hierarchy.h"
#include "multires/multires_solver.h"
#include "solver/gpu/gpu_conjugate_gradient.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace waxwork {

struct GpuMultiresReport {
    // Coarsest level first; per level, the three channels' BiCGSTAB results.
    std::vector<std::array<BicgstabResult, 3>> coarse_levels;
    std::array<ConjugateGradientResult, 3> fine;

    // The levels whose iterate was discarded (BiCGSTAB reverted to the start vector) per channel, as
    // MultiresSolveReport::fallback_reasons words them: "red: level 3: rho breakdown, start vector
    // kept; blue: ...". Empty when none was.
    std::string fallback_reasons() const;
};

class GpuMultiresSolver {
public:
    // `hierarchy` must have been built from `matrix` (build_multires_hierarchy). Needs a current
    // OpenGL >= 4.3 context for its lifetime; throws GpuError when the driver cannot run it.
    GpuMultiresSolver(const GlApi& gl, const DiffusionMatrix& matrix, const MultiresHierarchy& hierarchy);

    size_t size() const { return fine_.size(); }
    void set_light(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q) {
        fine_.set_light(matrix, q);
    }
    void set_right_hand_side(const std::array<std::vector<double>, 3>& b) { fine_.set_right_hand_side(b); }
    // Coarse-to-fine solve from scratch (the previous solution is not used). options as on the CPU;
    // on_iteration of the level-0 CG through `fine_options` (its tolerance and budget are taken from
    // `options`).
    GpuMultiresReport solve(const MultiresSolveOptions& options = {}, GpuCgOptions fine_options = {});
    // Replaces the resident solution (a start computed on the host, e.g. MultiresSolver's corrected
    // warm start, for solve_frame or solve_fine to continue from).
    void set_solution(const std::vector<std::array<double, 3>>& phi) { fine_.set_solution(phi); }
    // Level-0 CG only, at most `iteration_budget` iterations from the resident solution.
    bool solve_frame(int iteration_budget, double relative_tolerance) {
        return fine_.solve_frame(iteration_budget, relative_tolerance);
    }
    // After painting: `matrix` and `hierarchy` (this solver's, updated by MultiresSolver::update_values)
    // changed only in `level_rows` (its return value: rows per level). Uploads only those rows of
    // every level and refreshes the Jacobi diagonals: the device then holds exactly what a new solver
    // built on them would (bit for bit), for O(changed entries) of transfer instead of the hierarchy.
    // Throws InvalidArgumentError when the levels do not match the uploaded ones.
    void update_rows(const DiffusionMatrix& matrix, const MultiresHierarchy& hierarchy,
                     const std::vector<std::vector<int32_t>>& level_rows);
    std::vector<std::array<double, 3>> solution() const { return fine_.solution(); }
    const GpuBuffer& solution_buffer() const { return fine_.solution_buffer(); }
    // solve_frame with the per-channel results (a live editor reports iterations and error estimates).
    std::array<ConjugateGradientResult, 3> solve_fine(const GpuCgOptions& options) { return fine_.solve(options); }
    // The kernels the solution buffer belongs to (device radiance from the resident phi).
    GpuKernels& kernels() { return fine_.kernels(); }

private:
    struct Level {
        GpuMatrix matrix;
        GpuBuffer inv_diag, original_vertex;
        std::unique_ptr<GpuInterpolation> interpolation;  // from the next coarser level (none: coarsest)
        size_t rows;
    };
    GpuDiffusionSolver fine_;
    std::unique_ptr<GpuInterpolation> fine_interpolation_;  // level 1 -> level 0
    std::vector<Level> levels_;                              // hierarchy levels 1.. (levels_[0] is level 1)
};

}  // namespace waxwork
