#include "scene/live_solver.h"

#include "base/error.h"
#include "gl/gpu_compute.h"
#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/gpu_multires_solver.h"
#include "multires/multigrid_frame_solver.h"
#include "multires/multires_solver.h"
#include "solver/gpu/gpu_conjugate_gradient.h"
#include "solver/gpu/gpu_radiance.h"

#include <algorithm>
#include <iterator>
#include <limits>
#include <numeric>
#include <utility>

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

namespace {

// Adds channel c's skipped coarse levels, if any, to the notes of a coarse-to-fine pass ("red: level
// 3: ...; blue: ..."), which note_coarse_fallbacks shows.
void append_coarse_fallbacks(std::string& notes, int c, const MultiresSolveReport& report) {
    static constexpr const char* kChannelNames[] = {"red", "green", "blue"};
    if (const std::string reasons = report.fallback_reasons(); !reasons.empty())
        notes += (notes.empty() ? "" : "; ") + (kChannelNames[c] + (": " + reasons));
}

// The editor's iteration budget (Jacobi CG iterations per channel) in multigrid V-cycles, so that a
// budget costs about the same frame time in either method: one V-cycle for the three channels costs
// about as much as 4 Jacobi CG iterations on the three channels (bench/live_solver_bench.cpp, spot at
// 100K tets: 3.5-4 ms against 1.0 ms). For that time it does much more: relighting at budget 8, one
// frame per 3 degrees, leaves 0.08% (l2) error where Jacobi CG leaves 1.06%, in 16 ms frames instead
// of 19 ms (BM_RelightFrames). A positive budget runs at least one V-cycle.
constexpr int kIterationsPerVcycle = 4;

int vcycle_budget(int iteration_budget) {
    return iteration_budget <= 0 ? 0 : std::max(1, iteration_budget / kIterationsPerVcycle);
}

// A budget of `max_iterations` (> 0) and the `parts`-th share of what is left of `deadline` (bounded),
// for the solver objects that take a FrameBudget. A deadline already passed still gives a positive
// (vanishing) time limit: 0 would mean "no time limit", and the solver then runs its one iteration.
FrameBudget budget_until(const FrameDeadline& deadline, int parts, int max_iterations) {
    const double share = deadline.remaining() / std::max(parts, 1);
    return FrameBudget::milliseconds(std::max(share, std::numeric_limits<double>::denorm_min()), max_iterations);
}

// method_fallback_reason() when the multigrid V-cycle cannot be built or applied.
std::string jacobi_instead_of_multigrid(const std::exception& e) {
    return std::string("solving with Jacobi CG instead of multigrid CG: ") + e.what();
}

// `previous` rebuilt around an edit for `matrix` (rebuild_multires_hierarchy), or nothing when there is
// no previous hierarchy or the vertex map does not belong to it (then the caller builds from scratch).
std::optional<MultiresHierarchy> rebuilt_hierarchy(const MultiresHierarchy* previous,
                                                   std::span<const int32_t> new_of_old_vertex,
                                                   const DiffusionMatrix& matrix,
                                                   std::span<const Eigen::Vector3d> positions) {
    if (!previous || new_of_old_vertex.empty() || new_of_old_vertex.size() != previous->levels[0].size())
        return std::nullopt;
    return rebuild_multires_hierarchy(*previous, new_of_old_vertex, matrix, positions);
}

// The device multigrid's host operators for `matrix` after an edit: the hierarchy rebuilt from
// `previous_hierarchy` and the preconditioner rebuilt from `previous_preconditioner` (built on it),
// copying the rows the edit left unchanged; nothing without a fitting vertex map (the device solver
// then builds both). A preconditioner that cannot be built is left to the device solver's
// construction, which fails the same way and is reported there.
MultigridOperators rebuilt_multigrid_operators(const MultiresHierarchy* previous_hierarchy,
                                               const MultigridPreconditioner* previous_preconditioner,
                                               std::span<const int32_t> new_of_old_vertex, const DiffusionMatrix& matrix,
                                               std::span<const Eigen::Vector3d> positions,
                                               const MultigridOptions& options) {
    MultigridOperators operators;
    std::optional<MultiresHierarchy> hierarchy = rebuilt_hierarchy(previous_hierarchy, new_of_old_vertex, matrix, positions);
    if (!hierarchy) return operators;
    operators.hierarchy = std::make_unique<MultiresHierarchy>(std::move(*hierarchy));
    if (previous_preconditioner) {
        try {
            operators.preconditioner = std::make_unique<MultigridPreconditioner>(
                *operators.hierarchy, *previous_preconditioner, new_of_old_vertex, options);
        } catch (const AlgorithmError&) {
            operators.preconditioner.reset();
        }
    }
    return operators;
}

}  // namespace

struct LiveSolver::Gpu {
    // One of the three: Jacobi CG, the multigrid CG or the multires hierarchy.
    std::unique_ptr<GpuDiffusionSolver> solver;
    std::unique_ptr<GpuMultigridFrameSolver> multigrid;
    std::unique_ptr<GpuMultiresSolver> multires;
    std::vector<std::array<double, 3>> staging;  // interleaved phi for uploads and read-backs
    // Device radiance per shading vertex, with the rows, eta and q it was built and lit with: rebuilt
    // or re-lit when those differ (a new surface or shading, a painted eta, a new light).
    std::unique_ptr<GpuRadiance> radiance;
    RadianceRows radiance_rows;
    std::vector<std::array<double, 3>> radiance_q;

    size_t size() const { return solver ? solver->size() : multigrid ? multigrid->size() : multires->size(); }
    GpuKernels& kernels() { return solver ? solver->kernels() : multigrid ? multigrid->kernels() : multires->kernels(); }
    const GpuBuffer& solution_buffer() const {
        return solver ? solver->solution_buffer() : multigrid ? multigrid->solution_buffer() : multires->solution_buffer();
    }
};

LiveSolver::LiveSolver(const LiveSolverOptions& options)
    : method_(options.method), backend_(options.backend), requested_backend_(options.backend),
      context_(options.gl_context), multigrid_options_(options.multigrid),
      clock_(options.clock ? options.clock : MillisecondClock(steady_clock_milliseconds)) {}

LiveSolver::~LiveSolver() {
    try {
        release_gpu();
    } catch (...) {
        // Freeing device buffers cannot fail in a way the caller could act on.
    }
}

void LiveSolver::release_gpu() {
    if (!gpu_) return;
    if (context_) {
        const CurrentContext current(*context_);
        gpu_.reset();  // GpuBuffer frees with the context current
    } else {
        gpu_.reset();
    }
}

void LiveSolver::fall_back(const std::string& reason) {
    gpu_fallback_reason_ = reason;
    multires_pending_.solution = true;  // the CPU hierarchy has no warm start of its own yet
    backend_ = LiveBackend::Cpu;
    gpu_pending_ = PendingChanges{};  // no device to catch up any more
    gpu_level_rows_.clear();
    try {
        release_gpu();
    } catch (...) {
        gpu_.release();  // a context that cannot be made current any more: leak rather than crash
    }
}

void LiveSolver::PendingChanges::rows_changed(std::span<const int32_t> ascending_unique) {
    if (all_values) return;  // every row is re-sent anyway
    std::vector<int32_t> merged;
    merged.reserve(rows.size() + ascending_unique.size());
    std::set_union(rows.begin(), rows.end(), ascending_unique.begin(), ascending_unique.end(), std::back_inserter(merged));
    rows.swap(merged);
}

void LiveSolver::matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                                std::span<const int32_t> new_of_old_vertex) {
    eigenvalue_hint_ = {0, 0, 0};  // belong to the old matrix (a stale hint can be too optimistic)
    std::unique_ptr<MultigridFrameSolver> previous_multigrid = std::move(multigrid_);
    // The device multigrid's operators live on the host: the ones waiting for the next GPU frame, or
    // the device solver's (released below).
    const MultigridOperators previous_waiting = std::exchange(multigrid_waiting_, MultigridOperators{});
    const MultiresHierarchy* previous_device_hierarchy = nullptr;
    const MultigridPreconditioner* previous_device_preconditioner = nullptr;
    if (previous_waiting.hierarchy) {
        previous_device_hierarchy = previous_waiting.hierarchy.get();
        previous_device_preconditioner = previous_waiting.preconditioner.get();
    } else if (gpu_ && gpu_->multigrid) {
        previous_device_hierarchy = &gpu_->multigrid->hierarchy();
        previous_device_preconditioner = &gpu_->multigrid->preconditioner();
    }
    forget_estimates();
    // Every copy is rebuilt from this matrix: nothing of the old one is pending, b and phi are.
    multigrid_pending_ = multires_pending_ = gpu_pending_ = PendingChanges{};
    multigrid_positions_.clear();
    if (method_ == LiveMethod::MultigridCg && matrix.size() > 0) {
        if (mesh.vertex_count() != matrix.size())
            throw InvalidArgumentError("live solver: the matrix does not belong to the mesh");
        // Built now, while the mesh is at hand (the scene borrows it only during its calls); the device
        // solver at the next GPU frame, with the context current, from a copy of the rest positions.
        if (backend_ == LiveBackend::Cpu) {
            // The hierarchy rebuilt around the edit from the previous solver's, and the Galerkin rows
            // the edit left unchanged copied from its preconditioner; the previous solver is freed
            // once they are (at 500K tets the two together hold several hundred MB for a moment).
            std::optional<MultiresHierarchy> carried = rebuilt_hierarchy(
                previous_multigrid ? &previous_multigrid->hierarchy() : nullptr, new_of_old_vertex, matrix, mesh.positions);
            const MultigridFrameSolver* source = carried ? previous_multigrid.get() : nullptr;
            build_cpu_multigrid(mesh.positions, matrix, std::move(carried), source, new_of_old_vertex);
            previous_multigrid.reset();
        } else {
            multigrid_positions_ = mesh.positions;
            multigrid_waiting_ = rebuilt_multigrid_operators(previous_device_hierarchy, previous_device_preconditioner,
                                                             new_of_old_vertex, matrix, mesh.positions,
                                                             multigrid_options_);
            method_fallback_reason_.clear();
        }
    }
    const std::unique_ptr<MultiresSolver> previous = std::move(multires_);
    gpu_level_rows_.clear();
    // Built for either backend: the device copy is made from it, and a fallback keeps solving with it.
    if (method_ == LiveMethod::Multires && matrix.size() > 0) {
        if (mesh.vertex_count() != matrix.size())
            throw InvalidArgumentError("live solver: the matrix does not belong to the mesh");
        std::optional<MultiresHierarchy> carried =
            rebuilt_hierarchy(previous ? &previous->hierarchy() : nullptr, new_of_old_vertex, matrix, mesh.positions);
        multires_ = carried ? std::make_unique<MultiresSolver>(std::move(*carried))
                            : std::make_unique<MultiresSolver>(matrix, mesh.positions);
    }
    if (gpu_) {
        try {
            release_gpu();  // a new pattern: rebuilt at the next frame
        } catch (const std::exception& e) {
            fall_back(std::string("GPU solver: ") + e.what());
        }
    }
}

const MultigridPreconditioner* LiveSolver::multigrid_preconditioner() const {
    if (multigrid_) return &multigrid_->preconditioner();
    if (multigrid_waiting_.hierarchy) return multigrid_waiting_.preconditioner.get();
    return gpu_ && gpu_->multigrid ? &gpu_->multigrid->preconditioner() : nullptr;
}

const MultiresHierarchy* LiveSolver::multires_hierarchy() const {
    if (multires_) return &multires_->hierarchy();
    if (multigrid_) return &multigrid_->hierarchy();
    if (multigrid_waiting_.hierarchy) return multigrid_waiting_.hierarchy.get();
    return gpu_ && gpu_->multigrid ? &gpu_->multigrid->hierarchy() : nullptr;
}

void LiveSolver::build_cpu_multigrid(std::span<const Eigen::Vector3d> positions, const DiffusionMatrix& matrix,
                                     std::optional<MultiresHierarchy> hierarchy, const MultigridFrameSolver* previous,
                                     std::span<const int32_t> new_of_old_vertex) {
    try {
        FrameSolverOptions frame_options;
        frame_options.multigrid = multigrid_options_;
        multigrid_ = hierarchy ? std::make_unique<MultigridFrameSolver>(matrix, std::move(*hierarchy), frame_options,
                                                                        previous, new_of_old_vertex)
                               : std::make_unique<MultigridFrameSolver>(matrix, positions, frame_options);
        multigrid_pending_ = PendingChanges{};  // a new solver: b and phi to send
        method_fallback_reason_.clear();
    } catch (const AlgorithmError& e) {
        method_fallback_reason_ = jacobi_instead_of_multigrid(e);
    }
}

// Material changes keep the eigenvalue hints, as the CPU path always did: the stopping rule confirms
// convergence with the true residual anyway (conjugate_gradient.h).
void LiveSolver::values_changed() {
    forget_estimates();
    for (PendingChanges* pending : {&multigrid_pending_, &multires_pending_, &gpu_pending_}) pending->values_changed();
    gpu_level_rows_.clear();
    multigrid_waiting_ = MultigridOperators{};  // old values at level 0: the device solver builds afresh
}

void LiveSolver::forget_estimates() {
    multigrid_error_ = {1, 1, 1};
    multires_error_ = {1, 1, 1};
}

void LiveSolver::rows_changed(std::span<const int32_t> rows) {
    if (rows.empty()) return;
    forget_estimates();
    multigrid_waiting_ = MultigridOperators{};  // old values at level 0: the device solver builds afresh
    std::vector<int32_t> sorted(rows.begin(), rows.end());
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    // Only copies that exist (or, for the device, will at the next GPU frame) collect rows.
    if (multigrid_) multigrid_pending_.rows_changed(sorted);
    if (multires_) multires_pending_.rows_changed(sorted);
    if (backend_ == LiveBackend::Gpu) gpu_pending_.rows_changed(sorted);
}

void LiveSolver::right_hand_sides_changed() {
    gpu_pending_.right_hand_sides = true;
    multigrid_pending_.right_hand_sides = true;
    forget_estimates();
}
void LiveSolver::solution_changed() {
    gpu_pending_.solution = true;
    multigrid_pending_.solution = true;
    multires_pending_.solution = true;  // start from the new host phi, corrected coarse to fine
    forget_estimates();
}

std::string LiveSolver::description() const {
    std::string text;
    if (method_ == LiveMethod::Multires)
        text = backend_ == LiveBackend::Gpu ? "GPU multires, BiCGSTAB coarse to fine, warm CG per frame (float)"
                                            : "CPU multires, BiCGSTAB coarse to fine, warm CG per frame (double)";
    else
        text = gpu_multigrid()              ? "GPU multigrid CG, three channels per V-cycle (float)"
               : backend_ == LiveBackend::Gpu ? "GPU Jacobi CG (float)"
               : multigrid_                 ? "CPU multigrid CG, three channels per V-cycle"
                                            : "CPU Jacobi CG (double)";
    if (backend_ == LiveBackend::Gpu && !renderer_.empty()) text += " (" + renderer_ + ")";
    const MultigridPreconditioner* preconditioner =
        multigrid_ ? &multigrid_->preconditioner()
        : gpu_ && gpu_->multigrid ? &gpu_->multigrid->preconditioner()
                                  : nullptr;
    if (preconditioner && !preconditioner->lumping_fallback_reason().empty())
        text += ", absolute lumping (the row-sum setup failed)";
    return text;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate(const DiffusionMatrix& matrix,
                                                     const std::array<std::vector<double>, 3>& b,
                                                     std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                     double relative_tolerance, const std::array<bool, 3>& skip) {
    // A frame that uploads the whole matrix or runs the coarse-to-fine pass costs far more than its
    // iterations: measuring it would make the next time-budgeted frames much too short.
    const bool one_off_work = !gpu_ || gpu_pending_.all_values || (multires_ && multires_pending_.solution);
    if (multires_) update_multires_values(matrix);  // the host hierarchy first, whichever backend solves
    if (backend_ == LiveBackend::Gpu) {
        try {
            // Every GPU frame is measured, iteration-budgeted ones too: a switch to a time budget then
            // starts from what the device costs instead of a default.
            const double start = clock_();
            const bool multigrid = gpu_multigrid();  // its budgets need no prediction: not measured
            const auto out = iterate_gpu(matrix, b, phi, iteration_budget, relative_tolerance, skip);
            if (!one_off_work && !multigrid) {
                // The channels run in lockstep on the device: the frame cost the most any one ran.
                const int ran = std::max({out[0].iterations, out[1].iterations, out[2].iterations});
                gpu_iteration_time_.record(ran, clock_() - start);
            }
            return out;
        } catch (const GpuError& e) {
            fall_back(e.what());
        } catch (const AlgorithmError&) {
            throw;  // a breakdown is the system's, not the driver's: the CPU would report it too
        } catch (const Error& e) {
            fall_back(std::string("GPU solver: ") + e.what());  // e.g. no OpenGL 4.3 context
        }
        // The host phi is the last frame's read-back (iterate_gpu writes it only on success).
    }
    return iterate_cpu(matrix, b, phi, iteration_budget, relative_tolerance, skip);
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
    // The GPU cannot stop at a deadline: it runs the iterations predicted to fit (measured in the int
    // overload). The CPU runs up to the limit, stopped by deadline_.
    const int iterations = backend_ == LiveBackend::Gpu && !gpu_multigrid() ? gpu_iteration_time_.iterations_for(budget)
                           : budget.limits_iterations() ? budget.max_iterations
                                                        : std::numeric_limits<int>::max();
    return iterate(matrix, b, phi, iterations, relative_tolerance, skip);
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_cpu(const DiffusionMatrix& matrix,
                                                         const std::array<std::vector<double>, 3>& b,
                                                         std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                         double relative_tolerance, const std::array<bool, 3>& skip) {
    const size_t n = matrix.size();
    if (!multigrid_positions_.empty() && n > 0) {
        // After a GPU fallback the multigrid method goes on with the CPU multigrid CG (built here: the
        // device held the hierarchy), warm from the last read-back phi.
        // The hierarchy waiting for the device is this matrix's; its preconditioner goes (the CPU
        // solver builds its own).
        std::optional<MultiresHierarchy> waiting;
        if (multigrid_waiting_.hierarchy) {
            multigrid_waiting_.preconditioner.reset();
            waiting = std::move(*multigrid_waiting_.hierarchy);
        }
        multigrid_waiting_ = MultigridOperators{};
        build_cpu_multigrid(multigrid_positions_, matrix, std::move(waiting));
        multigrid_positions_.clear();
    }
    if (multigrid_ && n > 0) {
        try {
            return iterate_multigrid(matrix, b, phi, iteration_budget, relative_tolerance, skip);
        } catch (const AlgorithmError& e) {
            // phi is still the last frame's (the host copy is written only after a successful step).
            multigrid_.reset();
            method_fallback_reason_ = jacobi_instead_of_multigrid(e);
        }
    }
    if (multires_ && n > 0) return iterate_multires(b, phi, iteration_budget, relative_tolerance, skip);

    std::array<LiveSolverChannel, 3> out;
    int channels_left = static_cast<int>(std::count(skip.begin(), skip.end(), false));
    for (int c = 0; c < 3; ++c) {
        if (skip[c] || n == 0) {
            out[c].converged = true;
            out[c].estimated_relative_error = 0;
            continue;
        }
        ConjugateGradientOptions cg;
        cg.relative_tolerance = relative_tolerance;
        cg.max_iterations = iteration_budget;
        cg.smallest_eigenvalue_hint = eigenvalue_hint_[c];
        // The channels run one after the other: each gets its share of the frame's time left.
        cg.deadline = deadline_.share(channels_left--);
        const CsrMatrixView<double> view{n, matrix.offsets.data(), matrix.columns.data(), matrix.values[c].data()};
        const ConjugateGradientResult r = solve_jacobi_cg<double>(view, b[c], phi[c], cg);
        if (r.smallest_eigenvalue_estimate > 0) eigenvalue_hint_[c] = r.smallest_eigenvalue_estimate;
        out[c] = {r.iterations, r.estimated_relative_error, r.converged};
    }
    gpu_pending_.solution = true;  // the device no longer holds this phi
    return out;
}

std::array<LiveSolverChannel, 3> LiveSolver::multigrid_frame(MultigridFrameCg& solver, PendingChanges& pending,
                                                             const DiffusionMatrix& matrix,
                                                             const std::array<std::vector<double>, 3>& b,
                                                             std::array<std::vector<double>, 3>& phi,
                                                             int iteration_budget, double relative_tolerance,
                                                             const std::array<bool, 3>& skip,
                                                             const std::function<void()>& read_phi) {
    if (pending.all_values) {
        // All values on the kept pattern: every row changed (the hierarchy's graphs and Eq. 16 weights
        // depend on the pattern and rest positions only, so they stay).
        std::vector<int32_t> all(matrix.size());
        std::iota(all.begin(), all.end(), 0);
        solver.update_values(matrix, all);
    } else if (!pending.rows.empty()) {
        solver.update_values(matrix, pending.rows);  // paint: the changed rows and their coarse rows
    }
    pending.values_applied();
    if (pending.right_hand_sides) solver.set_right_hand_side({b[0], b[1], b[2]});
    pending.right_hand_sides = false;
    if (pending.solution) {
        // A zero phi is where the solver starts anyway (no product to form its residual).
        const bool zero = std::all_of(phi.begin(), phi.end(), [](const std::vector<double>& v) {
            return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; });
        });
        if (zero)
            solver.reset();
        else
            solver.set_phi({phi[0], phi[1], phi[2]});
    }
    pending.solution = false;
    solver.set_relative_tolerance(relative_tolerance);

    std::array<LiveSolverChannel, 3> out;
    int vcycles = 0;
    // The channels are solved together: a channel within the tolerance rides along with the others.
    if (!(skip[0] && skip[1] && skip[2]) && vcycle_budget(iteration_budget) > 0) {
        const FrameStep step = deadline_.bounded()
                                   ? solver.step(budget_until(deadline_, 1, vcycle_budget(iteration_budget)), clock_)
                                   : solver.step(vcycle_budget(iteration_budget));
        vcycles = step.vcycles;
        multigrid_error_ = step.estimated_relative_error;
        read_phi();  // the host copy: radiance, saves, cuts
    }
    for (int c = 0; c < 3; ++c) {
        if (skip[c]) {
            out[c] = {0, 0.0, true};
            continue;
        }
        // An estimate within the tolerance bounds the current phi's error even when it lags the last
        // update (the update only lowers the energy-norm error).
        out[c] = {vcycles, multigrid_error_[c], multigrid_error_[c] <= relative_tolerance};
    }
    return out;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_multigrid(const DiffusionMatrix& matrix,
                                                               const std::array<std::vector<double>, 3>& b,
                                                               std::array<std::vector<double>, 3>& phi,
                                                               int iteration_budget, double relative_tolerance,
                                                               const std::array<bool, 3>& skip) {
    MultigridFrameSolver& solver = *multigrid_;
    const auto out = multigrid_frame(solver, multigrid_pending_, matrix, b, phi, iteration_budget, relative_tolerance,
                                     skip, [&] {
                                         for (int c = 0; c < 3; ++c) {
                                             const std::span<const double> solved = solver.phi(c);
                                             std::copy(solved.begin(), solved.end(), phi[c].begin());
                                         }
                                     });
    gpu_pending_.solution = true;  // the device no longer holds this phi
    return out;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_gpu(const DiffusionMatrix& matrix,
                                                         const std::array<std::vector<double>, 3>& b,
                                                         std::array<std::vector<double>, 3>& phi, int iteration_budget,
                                                         double relative_tolerance, const std::array<bool, 3>& skip) {
    const size_t n = matrix.size();
    std::array<LiveSolverChannel, 3> out;
    if (n == 0 || (skip[0] && skip[1] && skip[2])) {
        for (int c = 0; c < 3; ++c) out[c] = {0, skip[c] ? 0.0 : 1.0, skip[c] || n == 0};
        return out;
    }
    if (!context_) context_ = open_headless_solver_context();
    const CurrentContext current(*context_);
    if (multires_) return iterate_gpu_multires(matrix, b, phi, iteration_budget, relative_tolerance);
    if (!multigrid_positions_.empty()) {
        try {
            return iterate_gpu_multigrid(matrix, b, phi, iteration_budget, relative_tolerance, skip);
        } catch (const AlgorithmError& e) {
            // The V-cycle cannot be built or applied: GPU Jacobi CG from the last frame's phi (the host
            // copy is written only after a successful step), until the next rebuild tries again.
            method_fallback_reason_ = jacobi_instead_of_multigrid(e);
            multigrid_positions_.clear();
            multigrid_waiting_ = MultigridOperators{};
            gpu_.reset();  // the context is current
            gpu_pending_ = PendingChanges{};
            // Its budget was counted in V-cycles, or unlimited under a deadline it no longer reads.
            if (deadline_.bounded())
                iteration_budget = gpu_iteration_time_.iterations_for(budget_until(deadline_, 1, iteration_budget));
        }
    }
    const GlApi& gl = context_->gl();
    if (!gpu_) {
        require_compute_support(gl);
        auto gpu = std::make_unique<Gpu>();
        gpu->solver = std::make_unique<GpuDiffusionSolver>(gl, matrix);
        gpu_ = std::move(gpu);
        const GLubyte* renderer = gl.GetString(GL_RENDERER);
        renderer_ = renderer ? reinterpret_cast<const char*>(renderer) : "";
        gpu_pending_ = PendingChanges{};  // a new device copy: the current values; b and phi to send
    } else if (gpu_pending_.all_values) {
        gpu_->solver->update_values(matrix);
    } else if (!gpu_pending_.rows.empty()) {
        gpu_->solver->update_rows(matrix, gpu_pending_.rows);  // paint: O(changed entries) upload
    }
    gpu_pending_.values_applied();
    if (gpu_pending_.right_hand_sides) gpu_->solver->set_right_hand_side(b);
    gpu_pending_.right_hand_sides = false;
    auto& staging = gpu_->staging;
    if (gpu_pending_.solution) {
        staging.resize(n);
        for (size_t v = 0; v < n; ++v)
            for (int c = 0; c < 3; ++c) staging[v][c] = phi[c][v];
        gpu_->solver->set_solution(staging);
    }
    gpu_pending_.solution = false;

    GpuCgOptions options;
    options.relative_tolerance = relative_tolerance;
    options.max_iterations = iteration_budget;
    options.use_eigenvalue_hints = true;
    const std::array<ConjugateGradientResult, 3> results = gpu_->solver->solve(options);
    staging = gpu_->solver->solution();
    for (size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) phi[c][v] = staging[v][c];
    for (int c = 0; c < 3; ++c) out[c] = {results[c].iterations, results[c].estimated_relative_error, results[c].converged};
    return out;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_gpu_multigrid(const DiffusionMatrix& matrix,
                                                                   const std::array<std::vector<double>, 3>& b,
                                                                   std::array<std::vector<double>, 3>& phi,
                                                                   int iteration_budget, double relative_tolerance,
                                                                   const std::array<bool, 3>& skip) {
    // Called by iterate_gpu with the context current. The same bookkeeping as iterate_multigrid, with
    // the device copy's record (gpu_pending_).
    const GlApi& gl = context_->gl();
    if (!gpu_) {
        require_compute_support(gl);
        FrameSolverOptions frame_options;
        frame_options.multigrid = multigrid_options_;
        auto gpu = std::make_unique<Gpu>();
        gpu->multigrid = multigrid_waiting_.hierarchy
                             ? std::make_unique<GpuMultigridFrameSolver>(
                                   gl, matrix, std::exchange(multigrid_waiting_, MultigridOperators{}), frame_options)
                             : std::make_unique<GpuMultigridFrameSolver>(gl, matrix, multigrid_positions_, frame_options);
        gpu_ = std::move(gpu);
        const GLubyte* renderer = gl.GetString(GL_RENDERER);
        renderer_ = renderer ? reinterpret_cast<const char*>(renderer) : "";
        gpu_pending_ = PendingChanges{};  // a new device copy: the current values; b and phi to send
    }
    GpuMultigridFrameSolver& solver = *gpu_->multigrid;
    return multigrid_frame(solver, gpu_pending_, matrix, b, phi, iteration_budget, relative_tolerance, skip,
                           [&] { phi = solver.phi(); });
}

void LiveSolver::update_multires_values(const DiffusionMatrix& matrix) {
    if (multires_pending_.all_values) {
        multires_->update_values(matrix);  // all values on the kept pattern and selection
        gpu_level_rows_.clear();           // gpu_pending_.all_values: the device takes every row
    } else if (!multires_pending_.rows.empty()) {
        // Paint: the changed level-0 rows and the Eq. 17 coarse rows that read them.
        const std::vector<std::vector<int32_t>> level_rows = multires_->update_values(matrix, multires_pending_.rows);
        if (backend_ == LiveBackend::Gpu && !gpu_pending_.all_values) {
            gpu_level_rows_.resize(std::max(gpu_level_rows_.size(), level_rows.size()));
            for (size_t l = 0; l < level_rows.size(); ++l) {
                std::vector<int32_t> merged;
                std::set_union(gpu_level_rows_[l].begin(), gpu_level_rows_[l].end(), level_rows[l].begin(),
                               level_rows[l].end(), std::back_inserter(merged));
                gpu_level_rows_[l].swap(merged);
            }
        }
    }
    multires_pending_.values_applied();
    gpu_pending_.rows.clear();  // the device copy of the hierarchy takes them per level (gpu_level_rows_)
}

void LiveSolver::note_coarse_fallbacks(const std::string& reasons) {
    // A skipped level costs level-0 iterations, not accuracy (the level-0 CG converges from any start),
    // but a user watching the multires method should know its coarse start did not work as meant.
    method_fallback_reason_ =
        reasons.empty() ? "" : "multires: the coarse-to-fine pass skipped " + reasons + " (level-0 CG converges regardless)";
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_multires(const std::array<std::vector<double>, 3>& b,
                                                              std::array<std::vector<double>, 3>& phi,
                                                              int iteration_budget, double relative_tolerance,
                                                              const std::array<bool, 3>& skip) {
    std::array<LiveSolverChannel, 3> out;
    if (iteration_budget > 0 && multires_pending_.solution) {
        // solve_frame then runs the coarse-to-fine pass: on its own from a zero phi (a new scene), as a
        // correction of the host phi otherwise (carried through a cut, or kept through a relaxation).
        multires_->reset_warm_start();
        for (int c = 0; c < 3; ++c)
            if (phi[c].size() == multires_->hierarchy().levels[0].size()) multires_->set_warm_start(c, phi[c]);
        multires_pending_.solution = false;
    }
    MultiresSolveOptions options;
    options.relative_tolerance = relative_tolerance;
    int channels_left = static_cast<int>(std::count(skip.begin(), skip.end(), false));
    std::string coarse_fallbacks;
    bool coarse_pass = false;
    for (int c = 0; c < 3; ++c) {
        if (skip[c]) {
            out[c] = {0, 0.0, true};
            continue;
        }
        const int parts = channels_left--;
        if (iteration_budget <= 0) {
            out[c] = {0, multires_error_[c], multires_error_[c] <= relative_tolerance};
            continue;
        }
        MultiresSolveReport report;
        // As for Jacobi CG: each channel's level-0 CG gets its share of the frame's time left.
        const std::span<const double> solved =
            deadline_.bounded() ? multires_->solve_frame(b[c], c, budget_until(deadline_, parts, iteration_budget),
                                                         &report, options, clock_)
                                : multires_->solve_frame(b[c], c, iteration_budget, &report, options);
        std::copy(solved.begin(), solved.end(), phi[c].begin());  // the host copy: radiance, saves, cuts
        if (!report.coarse_levels.empty()) {
            coarse_pass = true;
            append_coarse_fallbacks(coarse_fallbacks, c, report);
        }
        multires_error_[c] = report.fine.estimated_relative_error;
        out[c] = {report.fine.iterations, report.fine.estimated_relative_error, report.fine.converged};
    }
    if (coarse_pass) note_coarse_fallbacks(coarse_fallbacks);
    gpu_pending_.solution = true;  // the device no longer holds this phi
    return out;
}

std::array<LiveSolverChannel, 3> LiveSolver::iterate_gpu_multires(const DiffusionMatrix& matrix,
                                                                  const std::array<std::vector<double>, 3>& b,
                                                                  std::array<std::vector<double>, 3>& phi,
                                                                  int iteration_budget, double relative_tolerance) {
    // Called by iterate_gpu with the context current.
    const GlApi& gl = context_->gl();
    const MultiresHierarchy& hierarchy = multires_->hierarchy();
    if (!gpu_) {
        require_compute_support(gl);
        auto gpu = std::make_unique<Gpu>();
        gpu->multires = std::make_unique<GpuMultiresSolver>(gl, matrix, hierarchy);
        gpu_ = std::move(gpu);
        const GLubyte* renderer = gl.GetString(GL_RENDERER);
        renderer_ = renderer ? reinterpret_cast<const char*>(renderer) : "";
        gpu_pending_ = PendingChanges{};  // a new device copy: the current values; b to send
        gpu_level_rows_.clear();
        multires_pending_.solution = true;  // its phi starts at zero: start from the host phi (below)
    } else if (gpu_pending_.all_values) {
        // All values: every row of every level (the uploaded patterns stay).
        std::vector<std::vector<int32_t>> all(hierarchy.level_count());
        for (size_t l = 0; l < all.size(); ++l) {
            all[l].resize(hierarchy.levels[l].size());
            std::iota(all[l].begin(), all[l].end(), 0);
        }
        gpu_->multires->update_rows(matrix, hierarchy, all);
    } else if (!gpu_level_rows_.empty()) {
        gpu_->multires->update_rows(matrix, hierarchy, gpu_level_rows_);  // paint: O(changed entries)
    }
    gpu_pending_.values_applied();
    gpu_level_rows_.clear();
    if (gpu_pending_.right_hand_sides) gpu_->multires->set_right_hand_side(b);
    gpu_pending_.right_hand_sides = false;

    std::array<LiveSolverChannel, 3> out;
    if (iteration_budget <= 0) {
        for (int c = 0; c < 3; ++c) out[c] = {0, multires_error_[c], multires_error_[c] <= relative_tolerance};
        return out;
    }
    GpuCgOptions fine;
    fine.relative_tolerance = relative_tolerance;
    fine.max_iterations = iteration_budget;
    fine.use_eigenvalue_hints = true;
    std::array<ConjugateGradientResult, 3> results;
    if (multires_pending_.solution) {
        const bool warm = std::any_of(phi.begin(), phi.end(), [](const std::vector<double>& p) {
            return std::any_of(p.begin(), p.end(), [](double v) { return v != 0.0; });
        });
        if (warm) {
            // The host phi corrected coarse to fine (MultiresSolver::set_warm_start) on the host hierarchy
            // the device copy was made from, so both backends start the frame from the same vector; the
            // pass runs once per rebuild, and level 0 then iterates on the device.
            multires_->reset_warm_start();
            std::vector<std::array<double, 3>> start(phi[0].size());
            std::string coarse_fallbacks;
            for (int c = 0; c < 3; ++c) {
                multires_->set_warm_start(c, phi[c]);
                MultiresSolveReport report;
                const std::span<const double> corrected = multires_->solve_frame(b[c], c, 0, &report);
                for (size_t v = 0; v < start.size(); ++v) start[v][c] = corrected[v];
                append_coarse_fallbacks(coarse_fallbacks, c, report);
            }
            note_coarse_fallbacks(coarse_fallbacks);
            gpu_->multires->set_solution(start);
            results = gpu_->multires->solve_fine(fine);
        } else {
            MultiresSolveOptions options;
            options.relative_tolerance = relative_tolerance;
            options.max_iterations = iteration_budget;
            const GpuMultiresReport report = gpu_->multires->solve(options, fine);
            results = report.fine;
            note_coarse_fallbacks(report.fallback_reasons());
        }
        multires_pending_.solution = false;
    } else {
        results = gpu_->multires->solve_fine(fine);  // warm from the resident phi
    }
    auto& staging = gpu_->staging;
    staging = gpu_->multires->solution();
    const size_t n = staging.size();
    for (size_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) phi[c][v] = staging[v][c];
    for (int c = 0; c < 3; ++c) {
        multires_error_[c] = results[c].estimated_relative_error;
        out[c] = {results[c].iterations, results[c].estimated_relative_error, results[c].converged};
    }
    return out;
}

std::shared_ptr<const GpuBuffer> LiveSolver::radiance_on_device(const BoundarySurface& surface,
                                                                const ShadingSurface& shading,
                                                                const std::vector<std::array<double, 3>>& shading_q,
                                                                std::vector<std::array<float, 3>>* host_copy) {
    if (backend_ != LiveBackend::Gpu || !gpu_ || !context_ || shading.size() == 0) return nullptr;
    const size_t n = gpu_->size(), m = shading.size();
    if (shading_q.size() != m)
        throw InvalidArgumentError("live solver: radiance_on_device needs one light value per shading vertex");
    RadianceRows rows = shading_radiance_rows(surface, shading);
    try {
        const CurrentContext current(*context_);
        const GlApi& gl = context_->gl();
        GpuKernels& kernels = gpu_->kernels();
        if (!gpu_->radiance || gpu_->radiance_rows != rows) {
            gpu_->radiance.reset();  // frees its buffers with the context current
            gpu_->radiance = std::make_unique<GpuRadiance>(kernels, rows, n);
            gpu_->radiance_rows = std::move(rows);
            gpu_->radiance_q.clear();
        }
        if (gpu_->radiance_q != shading_q) {
            gpu_->radiance->set_light(shading_q);
            gpu_->radiance_q = shading_q;
        }
        auto e = std::make_shared<GpuBuffer>(gl, 3 * m * sizeof(float));
        gpu_->radiance->compute(gpu_->solution_buffer(), *e);
        if (host_copy) {
            const std::vector<float> values = e->download<float>();
            host_copy->resize(m);
            for (size_t s = 0; s < m; ++s)
                for (size_t c = 0; c < 3; ++c) (*host_copy)[s][c] = values[3 * s + c];
        }
        check_gpu_error(gl, "computing the radiance on the device");
        // The main window's context reads it next: the writes must be complete (a shared object's
        // changes are visible to another context only after the writing context finished them).
        gl.Finish();
        return e;
    } catch (const GpuError& e) {
        fall_back(e.what());
        return nullptr;
    }
}

}  // namespace waxwork
