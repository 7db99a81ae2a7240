#include "solver/petsc_distributed_solve.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/petsc_runtime.h"

#include <petscksp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

// CG's Lanczos coefficients give no trustworthy Ritz value before this iteration (as the serial
// solve's CgChannelState::kTrustedLanczosSteps).
constexpr PetscInt kTrustedLanczosSteps = 3;

// The PETSc objects of one solve, destroyed in any case.
struct Objects {
    Mat a = nullptr;
    Vec b = nullptr, x = nullptr, gathered = nullptr;
    KSP ksp = nullptr;
    VecScatter to_zero = nullptr;
    ~Objects() {
        if (to_zero) VecScatterDestroy(&to_zero);
        if (ksp) KSPDestroy(&ksp);
        if (gathered) VecDestroy(&gathered);
        if (x) VecDestroy(&x);
        if (b) VecDestroy(&b);
        if (a) MatDestroy(&a);
    }
};

struct ErrorEstimate {
    double tolerance = 0;
    Vec b = nullptr;
    PetscInt unknowns = 0;
    double estimate = std::numeric_limits<double>::infinity();
};

// KSP's convergence test: the estimated relative error in the energy norm (see the header).
PetscErrorCode estimated_error_test(KSP ksp, PetscInt iteration, PetscReal rnorm, KSPConvergedReason* reason,
                                    void* context) {
    auto& test = *static_cast<ErrorEstimate*>(context);
    *reason = KSP_CONVERGED_ITERATING;
    if (rnorm == 0) {  // b = 0 (phi = 0), or the exact solution
        test.estimate = 0;
        *reason = KSP_CONVERGED_ATOL;
        return 0;
    }
    if (iteration < kTrustedLanczosSteps && iteration < test.unknowns) return 0;
    PetscReal largest = 0, smallest = 0;
    PetscCall(KSPComputeExtremeSingularValues(ksp, &largest, &smallest));
    Vec x = nullptr;
    PetscCall(KSPBuildSolution(ksp, nullptr, &x));
    PetscScalar xb = 0;
    PetscCall(VecDot(x, test.b, &xb));
    if (!(smallest > 0) || !(xb > 0)) return 0;
    test.estimate = rnorm / std::sqrt(smallest) / std::sqrt(xb);
    if (test.estimate <= test.tolerance) *reason = KSP_CONVERGED_RTOL;
    return 0;
}

const char* option_prefix(PetscPeer peer) {
    return peer == PetscPeer::CgGamg ? "waxwork_mpi_gamg_" : "waxwork_mpi_boomeramg_";
}

}  // namespace

std::vector<std::array<double, 3>> solve_distributed(const OwnedRows& rows, size_t total_rows,
                                                     const DistributedSolveOptions& options,
                                                     DistributedSolveReport& report) {
    if (!(options.relative_tolerance > 0 && options.relative_tolerance < 1) || options.max_iterations <= 0)
        throw InvalidArgumentError("distributed solve: the tolerance must be in (0, 1) and the iteration cap positive");
    const auto owned = static_cast<size_t>(rows.range.size());
    if (rows.offsets.size() != owned + 1 || rows.inside_count.size() != owned || rows.outside_count.size() != owned ||
        static_cast<size_t>(rows.range.end) > total_rows ||
        total_rows > static_cast<size_t>(std::numeric_limits<PetscInt>::max()))
        throw InvalidArgumentError("distributed solve: the owned rows do not match a system of " +
                                   std::to_string(total_rows) + " rows");
    const PetscProcesses processes = petsc_processes();
    const auto m = static_cast<PetscInt>(owned), n = static_cast<PetscInt>(total_rows);
    report = {};

    // The preconditioner's settings as the peers use them; the norm is CG's natural one, which the
    // stopping rule reads (see the header), not the unpreconditioned one the comparison's cap uses.
    const std::string prefix = option_prefix(options.preconditioner);
    for (const auto& [key, value] : petsc_peer_settings(options.preconditioner))
        if (key != "ksp_norm_type")
            check_petsc(PetscOptionsSetValue(nullptr, ("-" + prefix + key).c_str(), value.c_str()),
                        "PetscOptionsSetValue");

    Objects o;
    std::vector<PetscInt> d_nnz(rows.inside_count.begin(), rows.inside_count.end());
    std::vector<PetscInt> o_nnz(rows.outside_count.begin(), rows.outside_count.end());
    check_petsc(MatCreateAIJ(PETSC_COMM_WORLD, m, m, n, n, 0, d_nnz.data(), 0, o_nnz.data(), &o.a), "MatCreateAIJ");
    // Exact preallocation: an entry outside it is a bug, not a reason to reallocate.
    check_petsc(MatSetOption(o.a, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
    check_petsc(MatCreateVecs(o.a, &o.x, &o.b), "MatCreateVecs");
    check_petsc(KSPCreate(PETSC_COMM_WORLD, &o.ksp), "KSPCreate");
    check_petsc(KSPSetOptionsPrefix(o.ksp, prefix.c_str()), "KSPSetOptionsPrefix");
    check_petsc(KSPSetFromOptions(o.ksp), "KSPSetFromOptions");
    check_petsc(KSPSetNormType(o.ksp, KSP_NORM_NATURAL), "KSPSetNormType");
    check_petsc(KSPSetComputeSingularValues(o.ksp, PETSC_TRUE), "KSPSetComputeSingularValues");
    check_petsc(KSPSetTolerances(o.ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, options.max_iterations),
                "KSPSetTolerances");
    ErrorEstimate test;
    test.tolerance = options.relative_tolerance;
    test.b = o.b;
    test.unknowns = n;
    check_petsc(KSPSetConvergenceTest(o.ksp, estimated_error_test, &test, nullptr), "KSPSetConvergenceTest");
    check_petsc(VecScatterCreateToZero(o.x, &o.to_zero, &o.gathered), "VecScatterCreateToZero");

    std::vector<std::array<double, 3>> phi;
    if (processes.rank == 0) phi.assign(total_rows, {0.0, 0.0, 0.0});
    std::vector<PetscInt> columns(rows.columns.begin(), rows.columns.end());
    for (int c = 0; c < 3; ++c) {
        const auto convert_start = std::chrono::steady_clock::now();
        for (size_t i = 0; i < owned; ++i) {
            const PetscInt row = rows.range.begin + static_cast<PetscInt>(i);
            const int32_t begin = rows.offsets[i];
            check_petsc(MatSetValues(o.a, 1, &row, rows.offsets[i + 1] - begin, columns.data() + begin,
                                     rows.values[c].data() + begin, INSERT_VALUES),
                        "MatSetValues");
        }
        check_petsc(MatAssemblyBegin(o.a, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
        check_petsc(MatAssemblyEnd(o.a, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
        check_petsc(MatSetOption(o.a, MAT_SPD, PETSC_TRUE), "MatSetOption");
        PetscScalar* b = nullptr;
        check_petsc(VecGetArrayWrite(o.b, &b), "VecGetArrayWrite");
        std::copy(rows.rhs[c].begin(), rows.rhs[c].end(), b);
        check_petsc(VecRestoreArrayWrite(o.b, &b), "VecRestoreArrayWrite");
        report.conversion_ms += milliseconds_since(convert_start);

        const auto setup_start = std::chrono::steady_clock::now();
        check_petsc(KSPSetOperators(o.ksp, o.a, o.a), "KSPSetOperators");
        check_petsc(KSPSetUp(o.ksp), "KSPSetUp (the preconditioner's setup)");
        report.preconditioner_ms += milliseconds_since(setup_start);

        const auto solve_start = std::chrono::steady_clock::now();
        test.estimate = std::numeric_limits<double>::infinity();
        check_petsc(KSPSolve(o.ksp, o.b, o.x), "KSPSolve");
        report.solve_ms += milliseconds_since(solve_start);
        PetscInt iterations = 0;
        check_petsc(KSPGetIterationNumber(o.ksp, &iterations), "KSPGetIterationNumber");
        KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
        check_petsc(KSPGetConvergedReason(o.ksp, &reason), "KSPGetConvergedReason");
        report.iterations[c] = static_cast<int>(iterations);
        report.estimated_relative_error[c] = test.estimate;
        if (reason <= 0) {
            const char* text = nullptr;
            KSPGetConvergedReasonString(o.ksp, &text);
            throw AlgorithmError(std::string("distributed solve: channel ") + "rgb"[c] + " did not converge to relative error " +
                                 std::to_string(options.relative_tolerance) + " (" + (text ? text : "?") + " after " +
                                 std::to_string(iterations) + " iterations, estimated error " +
                                 std::to_string(test.estimate) + "; check the mesh for slivers)");
        }

        const auto gather_start = std::chrono::steady_clock::now();
        check_petsc(VecScatterBegin(o.to_zero, o.x, o.gathered, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
        check_petsc(VecScatterEnd(o.to_zero, o.x, o.gathered, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
        if (processes.rank == 0) {
            const PetscScalar* x = nullptr;
            check_petsc(VecGetArrayRead(o.gathered, &x), "VecGetArrayRead");
            for (size_t i = 0; i < total_rows; ++i) phi[i][c] = x[i];
            check_petsc(VecRestoreArrayRead(o.gathered, &x), "VecRestoreArrayRead");
        }
        report.gather_ms += milliseconds_since(gather_start);
    }
    return phi;
}

}  // namespace waxwork
