#include "solver/petsc_peers.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/diffusion_matrix.h"
#include "solver/petsc_runtime.h"

#include <petscksp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <type_traits>

namespace waxwork {
namespace {

static_assert(std::is_same_v<PetscScalar, double>, "the peers need PETSc built with real double scalars");

void check(PetscErrorCode code, const char* call) { check_petsc(code, call); }

const char* option_prefix(PetscPeer peer) {
    return peer == PetscPeer::CgGamg ? "waxwork_gamg_" : "waxwork_boomeramg_";
}

void check_matrix(const DiffusionMatrix& matrix) {
    const size_t n = matrix.size();
    if (n == 0) throw InvalidArgumentError("PETSc peer: the matrix is empty");
    if (n > static_cast<size_t>(std::numeric_limits<PetscInt>::max()) ||
        matrix.nonzeros() > static_cast<size_t>(std::numeric_limits<PetscInt>::max()))
        throw InvalidArgumentError("PETSc peer: the matrix is larger than PETSc's index type allows");
    if (matrix.offsets.size() != n + 1 || matrix.offsets.front() != 0 ||
        static_cast<size_t>(matrix.offsets.back()) != matrix.nonzeros())
        throw InvalidArgumentError("PETSc peer: the matrix's row offsets do not match its size");
    for (size_t i = 0; i < n; ++i)
        if (matrix.offsets[i + 1] < matrix.offsets[i])
            throw InvalidArgumentError("PETSc peer: the matrix's row offsets decrease at row " + std::to_string(i));
    for (const int32_t column : matrix.columns)
        if (column < 0 || static_cast<size_t>(column) >= n)
            throw InvalidArgumentError("PETSc peer: a column index is outside the matrix");
    for (size_t c = 0; c < 3; ++c) {
        if (matrix.values[c].size() != matrix.nonzeros())
            throw InvalidArgumentError("PETSc peer: channel " + std::to_string(c) + " has " +
                                       std::to_string(matrix.values[c].size()) + " values for " +
                                       std::to_string(matrix.nonzeros()) + " entries");
        for (const double v : matrix.values[c])
            if (!std::isfinite(v))
                throw InvalidArgumentError("PETSc peer: channel " + std::to_string(c) + " has a non-finite value");
    }
}

}  // namespace

const char* petsc_peer_name(PetscPeer peer) {
    return peer == PetscPeer::CgGamg ? "petsc_cg_gamg" : "petsc_cg_boomeramg";
}

std::vector<std::pair<std::string, std::string>> petsc_peer_settings(PetscPeer peer) {
    if (peer == PetscPeer::CgGamg)
        return {{"ksp_type", "cg"},
                {"ksp_norm_type", "unpreconditioned"},
                {"pc_type", "gamg"},
                {"pc_gamg_type", "agg"},
                {"pc_gamg_agg_nsmooths", "1"},
                {"pc_gamg_threshold", "0.01"},
                {"pc_gamg_reuse_interpolation", "false"},
                {"mg_levels_ksp_type", "chebyshev"},
                {"mg_levels_pc_type", "jacobi"}};
    return {{"ksp_type", "cg"},
            {"ksp_norm_type", "unpreconditioned"},
            {"pc_type", "hypre"},
            {"pc_hypre_type", "boomeramg"},
            {"pc_hypre_boomeramg_coarsen_type", "HMIS"},
            {"pc_hypre_boomeramg_interp_type", "ext+i"},
            {"pc_hypre_boomeramg_strong_threshold", "0.25"},
            {"pc_hypre_boomeramg_agg_nl", "1"},
            {"pc_hypre_boomeramg_relax_type_down", "l1-Gauss-Seidel"},
            {"pc_hypre_boomeramg_relax_type_up", "backward-l1-Gauss-Seidel"},
            {"pc_hypre_boomeramg_relax_type_coarse", "Gaussian-elimination"}};
}

std::string petsc_version() {
    return "PETSc " + std::to_string(PETSC_VERSION_MAJOR) + "." + std::to_string(PETSC_VERSION_MINOR) + "." +
           std::to_string(PETSC_VERSION_SUBMINOR);
}

struct PetscPeerSolver::Impl {
    PetscPeer peer = PetscPeer::CgGamg;
    size_t n = 0;
    std::vector<int32_t> offsets, columns;  // the pattern built on, for rebuild's check
    std::array<Mat, 3> a{};
    std::array<KSP, 3> ksp{};
    Vec b = nullptr, x = nullptr;
    PetscSetupTimes times;

    ~Impl() {
        for (KSP& k : ksp)
            if (k) KSPDestroy(&k);
        for (Mat& m : a)
            if (m) MatDestroy(&m);
        if (b) VecDestroy(&b);
        if (x) VecDestroy(&x);
    }

    void set_up_preconditioners() {
        const auto start = std::chrono::steady_clock::now();
        for (size_t c = 0; c < 3; ++c) {
            check(KSPSetOperators(ksp[c], a[c], a[c]), "KSPSetOperators");
            check(KSPSetUp(ksp[c]), "KSPSetUp (the preconditioner's setup)");
        }
        times.preconditioner_ms = milliseconds_since(start);
    }
};

PetscPeerSolver::PetscPeerSolver(const DiffusionMatrix& matrix, PetscPeer peer) : impl_(std::make_unique<Impl>()) {
    check_matrix(matrix);
    ensure_petsc_runtime();
    Impl& s = *impl_;
    s.peer = peer;
    s.n = matrix.size();
    s.offsets = matrix.offsets;
    s.columns = matrix.columns;
    const auto n = static_cast<PetscInt>(s.n);

    // The options are set once per process under the peer's prefix, so that nothing a user sets for
    // another PETSc object applies here and the peers do not see each other's settings.
    const std::string prefix = option_prefix(peer);
    for (const auto& [key, value] : petsc_peer_settings(peer))
        check(PetscOptionsSetValue(nullptr, ("-" + prefix + key).c_str(), value.c_str()), "PetscOptionsSetValue");

    const auto convert_start = std::chrono::steady_clock::now();
    std::vector<PetscInt> row_offsets(matrix.offsets.begin(), matrix.offsets.end());
    std::vector<PetscInt> column_indices(matrix.columns.begin(), matrix.columns.end());
    for (size_t c = 0; c < 3; ++c) {
        check(MatCreate(PETSC_COMM_SELF, &s.a[c]), "MatCreate");
        check(MatSetSizes(s.a[c], n, n, n, n), "MatSetSizes");
        check(MatSetType(s.a[c], MATSEQAIJ), "MatSetType");
        // Copies the pattern and values and assembles; every stored entry is kept, so the AIJ value
        // array stays aligned with DiffusionMatrix::columns (both ascending per row) for rebuild().
        check(MatSeqAIJSetPreallocationCSR(s.a[c], row_offsets.data(), column_indices.data(), matrix.values[c].data()),
              "MatSeqAIJSetPreallocationCSR");
        check(MatSetOption(s.a[c], MAT_SPD, PETSC_TRUE), "MatSetOption");
    }
    s.times.conversion_ms = milliseconds_since(convert_start);

    check(MatCreateVecs(s.a[0], &s.x, &s.b), "MatCreateVecs");
    for (size_t c = 0; c < 3; ++c) {
        check(KSPCreate(PETSC_COMM_SELF, &s.ksp[c]), "KSPCreate");
        check(KSPSetOptionsPrefix(s.ksp[c], prefix.c_str()), "KSPSetOptionsPrefix");
        check(KSPSetOperators(s.ksp[c], s.a[c], s.a[c]), "KSPSetOperators");
        check(KSPSetFromOptions(s.ksp[c]), "KSPSetFromOptions");
    }
    s.set_up_preconditioners();
}

PetscPeerSolver::~PetscPeerSolver() = default;
PetscPeerSolver::PetscPeerSolver(PetscPeerSolver&&) noexcept = default;
PetscPeerSolver& PetscPeerSolver::operator=(PetscPeerSolver&&) noexcept = default;

void PetscPeerSolver::rebuild(const DiffusionMatrix& matrix) {
    Impl& s = *impl_;
    check_matrix(matrix);
    if (matrix.offsets != s.offsets || matrix.columns != s.columns)
        throw InvalidArgumentError("PETSc peer: rebuild needs the pattern the solver was built on");
    const auto convert_start = std::chrono::steady_clock::now();
    for (size_t c = 0; c < 3; ++c) {
        PetscScalar* values = nullptr;
        check(MatSeqAIJGetArrayWrite(s.a[c], &values), "MatSeqAIJGetArrayWrite");
        std::copy(matrix.values[c].begin(), matrix.values[c].end(), values);
        // Restoring the array advances the matrix's state, which makes KSPSetUp set the
        // preconditioner up again.
        check(MatSeqAIJRestoreArrayWrite(s.a[c], &values), "MatSeqAIJRestoreArrayWrite");
    }
    s.times.conversion_ms = milliseconds_since(convert_start);
    s.set_up_preconditioners();
}

const PetscSetupTimes& PetscPeerSolver::setup_times() const { return impl_->times; }
size_t PetscPeerSolver::size() const { return impl_->n; }
PetscPeer PetscPeerSolver::peer() const { return impl_->peer; }

PetscSolveReport PetscPeerSolver::solve(int channel, std::span<const double> b, std::span<double> x,
                                        const PetscSolveOptions& options) const {
    Impl& s = *impl_;
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("PETSc peer: channel " + std::to_string(channel) + " is not 0, 1 or 2");
    if (b.size() != s.n || x.size() != s.n)
        throw InvalidArgumentError("PETSc peer: right-hand side and solution need " + std::to_string(s.n) +
                                   " entries (got " + std::to_string(b.size()) + " and " + std::to_string(x.size()) + ")");
    if (!(options.relative_tolerance >= 0 && options.relative_tolerance < 1))
        throw InvalidArgumentError("PETSc peer: the relative tolerance must be in [0, 1)");
    if (options.max_iterations < 0)
        throw InvalidArgumentError("PETSc peer: the iteration cap must not be negative");
    if (!std::all_of(b.begin(), b.end(), [](double v) { return std::isfinite(v); }))
        throw InvalidArgumentError("PETSc peer: the right-hand side has a non-finite value");

    PetscSolveReport report;
    if (options.max_iterations == 0) {  // the zero start itself; PETSc is not asked for zero iterations
        std::fill(x.begin(), x.end(), 0.0);
        report.residual_norm = std::sqrt(std::inner_product(b.begin(), b.end(), b.begin(), 0.0));
        report.reason = "DIVERGED_ITS";
        return report;
    }

    PetscScalar* b_array = nullptr;
    check(VecGetArrayWrite(s.b, &b_array), "VecGetArrayWrite");
    std::copy(b.begin(), b.end(), b_array);
    check(VecRestoreArrayWrite(s.b, &b_array), "VecRestoreArrayWrite");

    KSP ksp = s.ksp[static_cast<size_t>(channel)];
    // abstol 0: only the relative tolerance (or the cap) stops CG; dtol: PETSc's default.
    check(KSPSetTolerances(ksp, options.relative_tolerance, 0.0, PETSC_DEFAULT, options.max_iterations),
          "KSPSetTolerances");
    check(KSPSolve(ksp, s.b, s.x), "KSPSolve");

    PetscInt iterations = 0;
    check(KSPGetIterationNumber(ksp, &iterations), "KSPGetIterationNumber");
    report.iterations = static_cast<int>(iterations);
    PetscReal residual = 0;
    check(KSPGetResidualNorm(ksp, &residual), "KSPGetResidualNorm");
    report.residual_norm = residual;
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
    const char* reason_text = nullptr;
    check(KSPGetConvergedReasonString(ksp, &reason_text), "KSPGetConvergedReasonString");
    report.reason = reason_text ? reason_text : "";
    report.converged = reason > 0;
    if (reason < 0 && reason != KSP_DIVERGED_ITS)
        throw AlgorithmError(std::string("PETSc peer ") + petsc_peer_name(s.peer) + ": CG stopped with " + report.reason +
                             " on channel " + std::to_string(channel) + " after " + std::to_string(report.iterations) +
                             " iterations");

    const PetscScalar* x_array = nullptr;
    check(VecGetArrayRead(s.x, &x_array), "VecGetArrayRead");
    std::copy(x_array, x_array + s.n, x.begin());
    check(VecRestoreArrayRead(s.x, &x_array), "VecRestoreArrayRead");
    return report;
}

}  // namespace waxwork
