// Peers of the Jacobi CG on the same matrix: Eigen's CG with an incomplete Cholesky preconditioner,
// and a sparse direct Cholesky (CHOLMOD supernodal when the build found it, Eigen's SimplicialLDLT
// otherwise). Used as references in tests and as baselines in bench/solver_bench.cpp.
#pragma once

#include "solver/conjugate_gradient.h"
#include "solver/diffusion_matrix.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <string>

namespace waxwork {

// The matrix of one channel as an Eigen column-major sparse matrix (the matrix is symmetric, so this
// is also its transpose).
Eigen::SparseMatrix<double> to_eigen_sparse(const DiffusionMatrix& matrix, int channel);
// Any compressed-row matrix (a hierarchy level, an interpolation operator) of `columns` columns
// (0: square) as an Eigen column-major sparse matrix.
Eigen::SparseMatrix<double> to_eigen_sparse(const CsrMatrixView<double>& matrix, size_t columns = 0);

struct EigenCgResult {
    int iterations = 0;
    double relative_residual = 0;  // Eigen's ||b - Mx|| / ||b||
};

// Eigen::ConjugateGradient<Lower|Upper, IncompleteCholesky<double>>; x is the warm start and result.
// residual_tolerance is Eigen's relative residual tolerance. Throws AlgorithmError if the incomplete
// factorisation fails.
EigenCgResult solve_eigen_cg_ic(const Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& b,
                                Eigen::VectorXd& x, double residual_tolerance, int max_iterations = 10000);

// A factorisation kept for repeated solves with the same matrix.
class DirectSolver {
public:
    // Factorises; throws AlgorithmError if the matrix is not positive definite.
    explicit DirectSolver(const Eigen::SparseMatrix<double>& matrix);
    ~DirectSolver();
    DirectSolver(const DirectSolver&) = delete;
    DirectSolver& operator=(const DirectSolver&) = delete;

    Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
    // "cholmod-supernodal" or "eigen-simplicial-ldlt".
    static std::string backend();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// The reference solution the benchmarks measure errors against: the direct solution of matrix x = b
// plus one step of iterative refinement (x += solve(b - matrix x)), which removes most of the
// factorisation's rounding. Throws as DirectSolver.
Eigen::VectorXd refined_direct_solution(const Eigen::SparseMatrix<double>& matrix, const Eigen::VectorXd& b);

}  // namespace waxwork
