#include "multires/cascadic_solver.h"

#include "base/error.h"
#include "base/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace waxwork {
namespace {

// Bornemann and Deuflhard's schedule: level l >= 1 runs level_iterations growth^(l - 1), capped.
int iterations_on_level(const CascadicOptions& options, size_t level) {
    const double count = options.level_iterations * std::pow(options.growth, static_cast<double>(level - 1));
    return static_cast<int>(std::min<double>(std::round(count), options.max_level_iterations));
}

}  // namespace

void validate(const CascadicOptions& options) {
    if (options.level_iterations < 0)
        throw InvalidArgumentError("cascadic solve: level_iterations " + std::to_string(options.level_iterations) +
                                   " is negative");
    if (!std::isfinite(options.growth) || options.growth < 1)
        throw InvalidArgumentError("cascadic solve: growth " + std::to_string(options.growth) +
                                   " must be a finite number >= 1");
    if (options.max_level_iterations < 0)
        throw InvalidArgumentError("cascadic solve: max_level_iterations " +
                                   std::to_string(options.max_level_iterations) + " is negative");
    if (!(options.relative_tolerance > 0 && options.relative_tolerance < 1))
        throw InvalidArgumentError("cascadic solve: relative_tolerance " + std::to_string(options.relative_tolerance) +
                                   " must be in (0, 1)");
    if (options.max_iterations < 0)
        throw InvalidArgumentError("cascadic solve: max_iterations " + std::to_string(options.max_iterations) +
                                   " is negative");
}

CascadicLevelReport iterate_level(const CsrMatrixView<double>& a, std::span<const double> b, std::span<double> x,
                                  int iterations) {
    CascadicLevelReport report;
    if (iterations <= 0) return report;
    const std::vector<double> start(x.begin(), x.end());
    try {
        report.iterations = solve_jacobi_cg<double>(a, b, x, exact_iteration_count(iterations)).iterations;
    } catch (const AlgorithmError& error) {
        std::copy(start.begin(), start.end(), x.begin());
        report.skipped = true;
        report.reason = error.what();
    }
    return report;
}

CascadicSolver::CascadicSolver(MultigridPreconditioner& operators) : operators_(operators) {
    const size_t levels = operators_.level_count();
    b_.resize(levels);
    x_.resize(levels);
    for (size_t l = 1; l < levels; ++l) {
        b_[l].resize(operators_.rows(l));
        x_[l].resize(operators_.rows(l));
    }
}

CascadicReport CascadicSolver::coarse_pass(std::span<const double> b, int channel, std::span<double> x,
                                           const CascadicOptions& options) {
    validate(options);
    if (channel < 0 || channel > 2)
        throw InvalidArgumentError("cascadic solve: channel " + std::to_string(channel) + " is not 0, 1 or 2");
    const size_t n0 = operators_.rows(0);
    if (b.size() != n0 || x.size() != n0)
        throw InvalidArgumentError("cascadic solve: vectors of size " + std::to_string(b.size()) + " and " +
                                   std::to_string(x.size()) + " for " + std::to_string(n0) + " vertices");
    for (size_t i = 0; i < n0; ++i)
        if (!std::isfinite(b[i]))
            throw AlgorithmError("cascadic solve: the right-hand side is not finite at vertex " + std::to_string(i));
    const auto start = std::chrono::steady_clock::now();
    CascadicReport report;
    const size_t levels = operators_.level_count();
    if (levels == 1) {  // level 0 is the coarsest: solved exactly
        operators_.solve_coarsest(channel, b, x);
        report.coarse_ms = milliseconds_since(start);
        return report;
    }
    // The Galerkin right-hand sides: b^{l+1} = (P^l)^T b^l.
    for (size_t l = 0; l + 1 < levels; ++l) {
        const std::span<const double> finer = l == 0 ? b : std::span<const double>(b_[l]);
        interpolate(operators_.transposed_interpolation(l), finer, b_[l + 1]);
    }
    operators_.solve_coarsest(channel, b_[levels - 1], x_[levels - 1]);
    report.coarse_levels.push_back({static_cast<int>(levels - 1), 0, false, {}});
    for (size_t l = levels - 1; l-- > 1;) {
        interpolate(operators_.interpolation(l), x_[l + 1], x_[l]);
        CascadicLevelReport entry = iterate_level(operators_.view(l, channel), b_[l], x_[l], iterations_on_level(options, l));
        entry.level = static_cast<int>(l);
        report.coarse_levels.push_back(std::move(entry));
    }
    interpolate(operators_.interpolation(0), x_[1], x);
    report.coarse_ms = milliseconds_since(start);
    return report;
}

CascadicReport CascadicSolver::solve(std::span<const double> b, int channel, std::span<double> x,
                                     const CascadicOptions& options) {
    CascadicReport report = coarse_pass(b, channel, x, options);
    const auto start = std::chrono::steady_clock::now();
    ConjugateGradientOptions cg;
    cg.relative_tolerance = options.relative_tolerance;
    cg.max_iterations = options.max_iterations;
    report.fine = solve_jacobi_cg<double>(operators_.view(0, channel), b, x, cg);
    report.fine_ms = milliseconds_since(start);
    return report;
}

}  // namespace waxwork
