// The live editor's multigrid-preconditioned CG (multires/multigrid_frame_solver.h) on the GPU: the
// three rgb channels solved together by CG whose preconditioner is the device V-cycle of
// gpu_multigrid_preconditioner.h, warm-started from the previous frame, within a budget of V-cycles or
// milliseconds. phi, b, r, p and q stay on the device between frames (rgb-interleaved float); the
// hierarchy and the Galerkin operators are built on the host and uploaded once.
//
// The same algorithm as the CPU frame solver, step for step: after each V-cycle z = B r the sums
// r . z and phi . M phi = phi . (b - r) give the energy-norm estimate (with lambda_min(B M) from CG's
// Lanczos matrix), p = z + beta p, q = M p with p . q, phi += alpha p, r -= alpha q; every
// residual_refresh_interval updates r = b - M phi is recomputed (in double on the host, see below) and
// CG restarts. The scalars and the stopping rule are the CPU's (multigrid_cg_state.h). A light change
// moves r by the change of b (no product with M); painting uploads the changed rows of every level.
//
// Per CG step: the V-cycle's dispatches, its coarsest solve round trip (a few KB, see
// gpu_multigrid_preconditioner.h), and two reductions read back (r . z with phi . M phi, then p . q),
// each a few KB. Because every step reads back anyway, a time budget is checked between V-cycles as on
// the CPU (one clock read each), unlike the Jacobi GPU solver, whose budget is predicted beforehand.
//
// Precision. Everything on the device is float (the V-cycle, as the CPU's default; phi, r and the
// products, where the CPU uses double). The recomputed residual r = b - M phi is not: it is formed on
// the host in double from the double matrix and b (a read-back of phi and an upload of r, every
// residual_refresh_interval updates), and a claim of convergence from the float recursive residual is
// confirmed with it before the solver stops (MultigridFrameCg::confirms_convergence). So the estimate
// measures the double system the CPU solves, not the float copy of M on the device, which on sliver
// meshes lies far from it (about 2e-4 relative at 1e-5 caps); each refresh corrects phi towards the double
// solution (mixed-precision iterative refinement). Where float phi cannot get within the tolerance,
// step() stops early with at_precision_floor. On well-shaped meshes the result agrees with the CPU
// double solution to ~1e-6 relative.
#pragma once

#include "multires/gpu_multigrid_preconditioner.h"
#include "multires/hierarchy.h"
#include "multires/multigrid_frame_cg.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "solver/frame_budget.h"
#include "solver/gpu/gpu_kernels.h"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace waxwork {

class GpuMultigridFrameSolver : public MultigridFrameCg {
public:
    // Builds the hierarchy and the preconditioner on the host (as MultigridFrameSolver) and uploads
    // them. The OpenGL context of `gl` (>= 4.3) must be current whenever the solver is used or
    // destroyed. Throws as MultigridFrameSolver's constructor, and GpuError when the driver fails.
    GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix, std::span<const Eigen::Vector3d> positions,
                            const FrameSolverOptions& options = {});
    // The same on a hierarchy built elsewhere for this matrix with options.hierarchy
    // (rebuild_multires_hierarchy after an edit). Throws InvalidArgumentError when its level 0 is not
    // the matrix's size or it was built with other options.
    GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix, MultiresHierarchy hierarchy,
                            const FrameSolverOptions& options = {});
    // The same on operators built on the host beforehand (a null preconditioner is built here). Throws
    // InvalidArgumentError also when there is no hierarchy or the preconditioner was built on another.
    GpuMultigridFrameSolver(const GlApi& gl, const DiffusionMatrix& matrix, MultigridOperators operators,
                            const FrameSolverOptions& options = {});
    ~GpuMultigridFrameSolver();

    // As MultigridFrameCg says, on the device's vectors (a driver error throws GpuError):
    // step(), set_relative_tolerance(), and these. The residual follows a change of b on the device;
    // update_values updates the host level 0 and preconditioner and uploads the changed rows of every
    // level.
    void set_right_hand_side(const std::array<std::span<const double>, 3>& b) override;
    void reset() override;
    void set_phi(const std::array<std::span<const double>, 3>& phi) override;
    void update_values(const DiffusionMatrix& matrix, std::span<const int32_t> changed_rows) override;

    // The current solution read back from the device, per channel.
    std::array<std::vector<double>, 3> phi() const;
    // phi on the device, 3 floats per vertex (rgb): what a renderer on the same context reads.
    const GpuBuffer& solution_buffer() const { return phi_; }
    GpuKernels& kernels() { return *kernels_; }

private:
    void precondition() override;
    MultigridCgState::StepSums step_sums() override;
    void set_direction(const Rgb& beta, bool restart) override;
    Rgb multiply_direction() override;
    void update_solution(const Rgb& alpha) override;
    std::array<double, 6> compute_residual(bool phi_is_zero) override;
    void steps_done() override;
    bool confirms_convergence() const override { return true; }
    // Uploads three host channels interleaved into `target`.
    void upload(const std::array<std::span<const double>, 3>& v, GpuBuffer& target);

    std::unique_ptr<GpuKernels> kernels_;
    std::unique_ptr<GpuMultigridPreconditioner> device_;
    GpuBuffer b_, r_, z_, p_, q_, phi_, scratch_;
    std::array<std::vector<double>, 3> host_b_;  // b in double, for the residual on the host
    std::vector<float> staging_;
};

}  // namespace waxwork
