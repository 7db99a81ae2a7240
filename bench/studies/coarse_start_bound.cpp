#include "bench/studies/coarse_start_bound.h"

#include "base/error.h"
#include "multires/multigrid_cg.h"
#include "solver/conjugate_gradient.h"
#include "solver/reference/reference_solvers.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

namespace waxwork {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

void require_level1(const MultiresHierarchy& hierarchy, const std::vector<double>& b) {
    if (hierarchy.level_count() < 2)
        throw InvalidArgumentError("coarse start bound: the hierarchy has no level 1 (" +
                                   std::to_string(hierarchy.levels.empty() ? 0 : hierarchy.levels[0].size()) +
                                   " vertices on level 0)");
    if (b.size() != hierarchy.levels[0].size())
        throw InvalidArgumentError("coarse start bound: right-hand side has " + std::to_string(b.size()) +
                                   " entries, level 0 has " + std::to_string(hierarchy.levels[0].size()));
}

// P^0 (Eq. 16) as an Eigen matrix, level-0 rows by level-1 columns.
SparseMatrix interpolation_matrix(const MultiresHierarchy& hierarchy) {
    const InterpolationOperator& p = hierarchy.levels[0].interpolation;
    return to_eigen_sparse(CsrMatrixView<double>{p.rows(), p.offsets.data(), p.columns.data(), p.weights.data()},
                           hierarchy.levels[1].size());
}

std::vector<double> to_std(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

Eigen::Map<const Eigen::VectorXd> as_eigen(const std::vector<double>& v) {
    return {v.data(), static_cast<Eigen::Index>(v.size())};
}

void check_channel(int channel) {
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("coarse start bound: channel " + std::to_string(channel) + " is not 0, 1 or 2");
}

ChannelVectors interpolated(const MultiresHierarchy& hierarchy, const ChannelVectors& coarse) {
    ChannelVectors fine;
    for (size_t c = 0; c < 3; ++c) {
        fine[c].resize(hierarchy.levels[0].size());
        interpolate(hierarchy.levels[0].interpolation, coarse[c], fine[c]);
    }
    return fine;
}

}  // namespace

double combined_relative_error(const ChannelVectors& x, const ChannelVectors& reference) {
    double error = 0, norm = 0;
    for (size_t c = 0; c < 3; ++c) {
        error += (as_eigen(x[c]) - as_eigen(reference[c])).squaredNorm();
        norm += as_eigen(reference[c]).squaredNorm();
    }
    return std::sqrt(error / norm);
}

std::vector<double> solve_level1_eq17(const MultiresHierarchy& hierarchy, int channel, const std::vector<double>& b) {
    require_level1(hierarchy, b);
    check_channel(channel);
    const HierarchyLevel& coarse = hierarchy.levels[1];
    Eigen::VectorXd injected(static_cast<Eigen::Index>(coarse.size()));
    for (size_t i = 0; i < coarse.size(); ++i)
        injected[static_cast<Eigen::Index>(i)] = b[static_cast<size_t>(coarse.parent_vertex[i])];  // Eq. 17
    Eigen::SparseLU<SparseMatrix> lu;
    lu.compute(to_eigen_sparse(coarse.view(channel)));  // not symmetric: LU, not Cholesky
    if (lu.info() != Eigen::Success)
        throw AlgorithmError("coarse start bound: level 1's Eq. 17 matrix is singular (" + lu.lastErrorMessage() + ")");
    return to_std(lu.solve(injected));
}

std::vector<double> solve_level1_galerkin(const MultiresHierarchy& hierarchy, int channel, const std::vector<double>& b) {
    require_level1(hierarchy, b);
    check_channel(channel);
    const SparseMatrix p = interpolation_matrix(hierarchy);
    const SparseMatrix pt = p.transpose();
    const SparseMatrix galerkin = pt * to_eigen_sparse(hierarchy.levels[0].view(channel)) * p;
    Eigen::SimplicialLDLT<SparseMatrix> ldlt(galerkin);
    if (ldlt.info() != Eigen::Success)
        throw AlgorithmError("coarse start bound: the Galerkin level-1 matrix is not positive definite");
    return to_std(ldlt.solve(Eigen::VectorXd(pt * as_eigen(b))));
}

namespace {

// The smallest k <= max_iterations with error_after(k) <= target_error, by doubling and bisection
// (error_after taken as non-increasing in k); -1 when max_iterations does not reach it.
int smallest_count_to(const std::function<double(int)>& error_after, double target_error, int max_iterations) {
    if (error_after(0) <= target_error) return 0;
    int hi = 1;
    while (error_after(hi) > target_error) {
        if (hi >= max_iterations) return -1;
        hi = std::min(2 * hi, max_iterations);
    }
    int lo = hi / 2;  // error_after(lo) > target (lo = 0 was tested above)
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        (error_after(mid) <= target_error ? hi : lo) = mid;
    }
    return hi;
}

}  // namespace

int jacobi_cg_iterations_to(const MultiresHierarchy& hierarchy, const ChannelVectors& b, const ChannelVectors& start,
                            const ChannelVectors& reference, double target_error, int max_iterations) {
    const HierarchyLevel& fine = hierarchy.levels[0];
    ChannelVectors x;
    const auto error_after = [&](int iterations) {
        for (size_t c = 0; c < 3; ++c) {
            x[c] = start[c];
            if (iterations > 0) solve_jacobi_cg<double>(fine.view(static_cast<int>(c)), b[c], x[c], exact_iteration_count(iterations));
        }
        return combined_relative_error(x, reference);
    };
    return smallest_count_to(error_after, target_error, max_iterations);
}

int multigrid_cg_iterations_to(MultigridPreconditioner& preconditioner, const ChannelVectors& b,
                               const ChannelVectors& reference, double target_error, int max_iterations) {
    ChannelVectors x;
    const auto error_after = [&](int iterations) {
        for (size_t c = 0; c < 3; ++c) {
            x[c].assign(b[c].size(), 0.0);
            if (iterations > 0) solve_multigrid_cg(preconditioner, static_cast<int>(c), b[c], x[c], exact_iteration_count(iterations));
        }
        return combined_relative_error(x, reference);
    };
    return smallest_count_to(error_after, target_error, max_iterations);
}

CoarseStartBound measure_coarse_start_bound(const MultiresHierarchy& hierarchy, const ChannelVectors& b,
                                            const ChannelVectors& reference, double target_error, int max_iterations) {
    if (!(target_error > 0 && target_error < 1))
        throw InvalidArgumentError("coarse start bound: target error " + std::to_string(target_error) +
                                   " is not in (0, 1)");
    for (size_t c = 0; c < 3; ++c) {
        require_level1(hierarchy, b[c]);
        if (reference[c].size() != b[c].size())
            throw InvalidArgumentError("coarse start bound: reference and right-hand side sizes differ");
    }
    const HierarchyLevel& coarse = hierarchy.levels[1];
    CoarseStartBound bound;
    bound.fine_vertices = hierarchy.levels[0].size();
    bound.coarse_vertices = coarse.size();

    ChannelVectors restricted, eq17, galerkin, zero;
    for (size_t c = 0; c < 3; ++c) {
        restricted[c].resize(coarse.size());
        for (size_t i = 0; i < coarse.size(); ++i) restricted[c][i] = reference[c][static_cast<size_t>(coarse.parent_vertex[i])];
        eq17[c] = solve_level1_eq17(hierarchy, static_cast<int>(c), b[c]);
        galerkin[c] = solve_level1_galerkin(hierarchy, static_cast<int>(c), b[c]);
        zero[c].assign(b[c].size(), 0.0);
    }
    bound.interpolation_error = combined_relative_error(interpolated(hierarchy, restricted), reference);
    const ChannelVectors eq17_start = interpolated(hierarchy, eq17);
    const ChannelVectors galerkin_start = interpolated(hierarchy, galerkin);
    bound.eq17_start_error = combined_relative_error(eq17_start, reference);
    bound.galerkin_start_error = combined_relative_error(galerkin_start, reference);
    bound.iterations_from_zero = jacobi_cg_iterations_to(hierarchy, b, zero, reference, target_error, max_iterations);
    bound.iterations_from_eq17 = jacobi_cg_iterations_to(hierarchy, b, eq17_start, reference, target_error, max_iterations);
    bound.iterations_from_galerkin =
        jacobi_cg_iterations_to(hierarchy, b, galerkin_start, reference, target_error, max_iterations);
    return bound;
}

}  // namespace waxwork
