#include "scene/live_solver.h"

#include "base/error.h"
#include "scene/gpu_jacobi_frame_solver.h"
#include "scene/gpu_multigrid_frame_adapter.h"
#include "scene/gpu_multires_frame_adapter.h"
#include "scene/jacobi_frame_solver.h"
#include "scene/multigrid_frame_adapter.h"
#include "scene/multires_frame_adapter.h"

#include <algorithm>
#include <limits>

namespace waxwork {

const char* live_method_name(LiveMethod method) {
    switch (method) {
        case LiveMethod::MultigridCg: return "mgcg";
        case LiveMethod::Multires: return "multires";
        case LiveMethod::JacobiCg: break;
    }
    return "jacobi";
}
const char* live_backend_name(LiveBackend backend) { return backend == LiveBackend::Gpu ? "gpu" : "cpu"; }

LiveMethod parse_live_method(const std::string& name) {
    if (name == "jacobi") return LiveMethod::JacobiCg;
    if (name == "mgcg") return LiveMethod::MultigridCg;
    if (name == "multires") return LiveMethod::Multires;
    throw InvalidArgumentError("live solver: unknown method '" + name + "' (jacobi, mgcg or multires)");
}

LiveBackend parse_live_backend(const std::string& name) {
    if (name == "cpu") return LiveBackend::Cpu;
    if (name == "gpu") return LiveBackend::Gpu;
    throw InvalidArgumentError("live solver: unknown backend '" + name + "' (cpu or gpu)");
}

LiveSolver::LiveSolver(const LiveSolverOptions& options)
    : method_(options.method), backend_(options.backend), requested_backend_(options.backend),
      multigrid_options_(options.multigrid),
      clock_(options.clock ? options.clock : MillisecondClock(steady_clock_milliseconds)),
      gpu_context_(options.gl_context), solver_(make_frame_solver(LiveMethod::JacobiCg)),
      runs_method_(method_ == LiveMethod::JacobiCg) {}

LiveSolver::~LiveSolver() = default;  // each GPU implementation frees its device objects with the context current

std::unique_ptr<FrameSolver> LiveSolver::make_frame_solver(LiveMethod method) {
    const bool gpu = backend_ == LiveBackend::Gpu;
    switch (method) {
        case LiveMethod::MultigridCg:
            if (gpu) return std::make_unique<GpuMultigridFrameAdapter>(gpu_context_, multigrid_options_);
            return std::make_unique<MultigridFrameAdapter>(multigrid_options_);
        case LiveMethod::Multires:
            if (gpu) return std::make_unique<GpuMultiresFrameAdapter>(gpu_context_);
            return std::make_unique<MultiresFrameAdapter>();
        case LiveMethod::JacobiCg: break;
    }
    if (gpu) return std::make_unique<GpuJacobiFrameSolver>(gpu_context_);
    return std::make_unique<JacobiFrameSolver>();
}

void LiveSolver::fall_back(const std::string& reason) {
    gpu_fallback_reason_ = reason;
    backend_ = LiveBackend::Cpu;
    // The GPU implementation is freed here (or leaked, when its context cannot be made current any more).
    solver_ = solver_->cpu_successor();
}

void LiveSolver::use_jacobi_instead(const std::exception& e) {
    method_fallback_reason_ = std::string("solving with Jacobi CG instead of multigrid CG: ") + e.what();
    solver_ = make_frame_solver(LiveMethod::JacobiCg);
    runs_method_ = false;
}

void LiveSolver::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                std::span<const int32_t> new_of_old_vertex) {
    if (method_ != LiveMethod::JacobiCg && matrix.size() > 0 && mesh.vertex_count() != matrix.size())
        throw InvalidArgumentError("live solver: the matrix does not belong to the mesh");
    if (!runs_method_) {
        solver_ = make_frame_solver(method_);
        runs_method_ = true;
    }
    if (method_ == LiveMethod::MultigridCg && matrix.size() > 0) method_fallback_reason_.clear();
    try {
        solver_->matrix_rebuilt(mesh, matrix, new_of_old_vertex);
    } catch (const GpuError& e) {
        fall_back(e.what());  // the device copy of the old matrix could not be freed
    } catch (const AlgorithmError& e) {
        if (method_ != LiveMethod::MultigridCg) throw;
        use_jacobi_instead(e);  // the CPU multigrid is built here
    }
}

void LiveSolver::values_changed() { solver_->values_changed(); }

void LiveSolver::rows_changed(std::span<const int32_t> rows) {
    if (rows.empty()) return;
    std::vector<int32_t> sorted(rows.begin(), rows.end());
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    solver_->rows_changed(sorted);
}

void LiveSolver::right_hand_sides_changed() { solver_->right_hand_sides_changed(); }
void LiveSolver::solution_changed() { solver_->solution_changed(); }

const MultigridPreconditioner* LiveSolver::multigrid_preconditioner() const {
    return solver_->multigrid_preconditioner();
}
const MultiresHierarchy* LiveSolver::multires_hierarchy() const { return solver_->multires_hierarchy(); }
std::string LiveSolver::description() const { return solver_->description(); }

std::array<LiveSolverChannel, 3> LiveSolver::iterate(const DiffusionMatrix& matrix,
                                                     const std::array<std::vector<double>, 3>& b,
                                                     std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                     double relative_tolerance, const std::array<bool, 3>& skip) {
    // A frame that uploads the whole matrix or runs the coarse-to-fine pass costs far more than its
    // iterations: measuring it would make the next time-budgeted frames much too short.
    const bool measured = solver_->next_frame_measures_iterations();
    solver_->apply_host_changes(matrix);  // the host hierarchy first, whichever backend solves
    if (backend_ == LiveBackend::Gpu) {
        try {
            // Every GPU frame is measured, iteration-budgeted ones too: a switch to a time budget then
            // starts from what the device costs instead of a default.
            const double start = clock_();
            const FrameResult out = run_frame(matrix, b, phi, iteration_budget, relative_tolerance, skip);
            if (measured) {
                // The channels run in lockstep on the device: the frame cost the most any one ran.
                const auto& c = out.channels;
                const int ran = std::max({c[0].iterations, c[1].iterations, c[2].iterations});
                gpu_iteration_time_.record(ran, clock_() - start);
            }
            return out.channels;
        } catch (const GpuError& e) {
            fall_back(e.what());
        } catch (const AlgorithmError&) {
            throw;  // a breakdown is the system's, not the driver's: the CPU would report it too
        } catch (const Error& e) {
            fall_back(std::string("GPU solver: ") + e.what());  // e.g. no OpenGL 4.3 context
        }
        // The host phi is the last frame's read-back (a GPU frame writes it only on success).
    }
    return run_frame(matrix, b, phi, iteration_budget, relative_tolerance, skip).channels;
}

FrameResult LiveSolver::run_frame(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                                    std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                    double relative_tolerance, const std::array<bool, 3>& skip) {
    FrameResult result;
    try {
        result = solver_->iterate(matrix, b, phi, FrameLimits{iteration_budget, deadline_, clock_}, relative_tolerance,
                                  skip);
    } catch (const AlgorithmError& e) {
        if (method_ != LiveMethod::MultigridCg || !runs_method_) throw;
        // phi is still the last frame's (the host copy is written only after a successful step).
        use_jacobi_instead(e);
        // The multigrid's budget was counted in V-cycles, or unlimited under a deadline a device Jacobi
        // CG cannot read.
        if (!solver_->checks_deadline() && deadline_.bounded())
            iteration_budget = gpu_iteration_time_.iterations_for(budget_until(deadline_, 1, iteration_budget));
        result = solver_->iterate(matrix, b, phi, FrameLimits{iteration_budget, deadline_, clock_}, relative_tolerance,
                                  skip);
    }
    if (result.method_note) method_fallback_reason_ = *result.method_note;
    return result;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate(const DiffusionMatrix& matrix,
                                                     const std::array<std::vector<double>, 3>& b,
                                                     std::array<std::vector<double>, 3>& phi, const FrameBudget& budget,
                                                     double relative_tolerance, const std::array<bool, 3>& skip) {
    validate(budget);
    deadline_ = FrameDeadline::of(budget, clock_);
    // The deadline belongs to this frame only: int-budget frames after it (or after a throw) have none.
    struct ClearDeadline {
        FrameDeadline& deadline;
        ~ClearDeadline() { deadline = FrameDeadline{}; }
    } clear{deadline_};
    // A device that cannot stop at a deadline runs the iterations predicted to fit (measured in the int
    // overload); the others run up to the limit, stopped by deadline_.
    const int iterations = !solver_->checks_deadline() ? gpu_iteration_time_.iterations_for(budget)
                           : budget.limits_iterations() ? budget.max_iterations
                                                        : std::numeric_limits<int>::max();
    return iterate(matrix, b, phi, iterations, relative_tolerance, skip);
}

std::shared_ptr<const GpuBuffer> LiveSolver::radiance_on_device(const BoundarySurface& surface,
                                                                const ShadingSurface& shading,
                                                                const std::vector<std::array<double, 3>>& shading_q,
                                                                std::vector<std::array<float, 3>>* host_copy) {
    if (backend_ != LiveBackend::Gpu) return nullptr;
    try {
        return solver_->radiance_on_device(surface, shading, shading_q, host_copy);
    } catch (const GpuError& e) {
        fall_back(e.what());
        return nullptr;
    }
}

}  // namespace waxwork
