#include "solver/reference/reference_solvers.h"

#include "base/error.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#ifdef WAXWORK_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <vector>

namespace waxwork {

Eigen::SparseMatrix<double> to_eigen_sparse(const DiffusionMatrix& m, int channel) {
    if (channel < 0 || channel > 2) throw InvalidArgumentError("to_eigen_sparse: channel must be 0, 1 or 2");
    return to_eigen_sparse(CsrMatrixView<double>{m.size(), m.offsets.data(), m.columns.data(),
                                                 m.values[static_cast<size_t>(channel)].data()});
}

Eigen::SparseMatrix<double> to_eigen_sparse(const CsrMatrixView<double>& m, size_t columns) {
    const auto rows = static_cast<Eigen::Index>(m.rows);
    Eigen::SparseMatrix<double> a(rows, columns == 0 ? rows : static_cast<Eigen::Index>(columns));
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(m.rows == 0 ? 0 : static_cast<size_t>(m.offsets[m.rows]));
    for (Eigen::Index i = 0; i < rows; ++i)
        for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k)
            triplets.emplace_back(static_cast<int>(i), m.columns[k], m.values[k]);
    a.setFromTriplets(triplets.begin(), triplets.end());
    return a;
}

EigenCgResult solve_eigen_cg_ic(const Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                double residual_tolerance, int max_iterations) {
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>>
        cg;
    cg.setTolerance(residual_tolerance);
    cg.setMaxIterations(max_iterations);
    cg.compute(matrix);
    if (cg.info() != Eigen::Success) throw AlgorithmError("Eigen CG: incomplete Cholesky factorisation failed");
    x = cg.solveWithGuess(b, x);
    if (!x.allFinite()) throw AlgorithmError("Eigen CG: non-finite solution");
    return {static_cast<int>(cg.iterations()), cg.error()};
}

#ifdef WAXWORK_HAVE_CHOLMOD
struct DirectSolver::Impl {
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> solver;
};
std::string DirectSolver::backend() { return "cholmod-supernodal"; }
#else
struct DirectSolver::Impl {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
};
std::string DirectSolver::backend() { return "eigen-simplicial-ldlt"; }
#endif

DirectSolver::DirectSolver(const Eigen::SparseMatrix<double>& matrix) : impl_(std::make_unique<Impl>()) {
    impl_->solver.compute(matrix);
    if (impl_->solver.info() != Eigen::Success)
        throw AlgorithmError("direct solver (" + backend() + "): factorisation failed (matrix not positive definite)");
}

DirectSolver::~DirectSolver() = default;

Eigen::VectorXd DirectSolver::solve(const Eigen::VectorXd& b) const {
    Eigen::VectorXd x = impl_->solver.solve(b);
    if (impl_->solver.info() != Eigen::Success || !x.allFinite())
        throw AlgorithmError("direct solver (" + backend() + "): solve failed");
    return x;
}

Eigen::VectorXd refined_direct_solution(const Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& b) {
    const DirectSolver direct(matrix);
    Eigen::VectorXd x = direct.solve(b);
    x += direct.solve(b - matrix * x);
    return x;
}

}  // namespace waxwork
