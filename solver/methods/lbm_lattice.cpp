#include "solver/methods/lbm_lattice.h"

#include "base/error.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace waxwork {
namespace {

constexpr size_t kGrain = 1024;

// Populations stored per cell, direction, channel: one cell's 18 doubles are contiguous.
size_t slot(size_t cell, int direction) { return (cell * kLbmDirections + static_cast<size_t>(direction)) * 3; }

// The gradient of rho at cell c in cells (per unit of cell size), from the neighbours along each axis.
std::array<std::array<double, 3>, 3> gradient(const LbmLattice& lattice, const std::vector<std::array<double, 3>>& rho,
                                              size_t c) {
    std::array<std::array<double, 3>, 3> g{};  // [axis][channel]
    for (int axis = 0; axis < 3; ++axis) {
        const int32_t up = lattice.next[2 * axis][c], down = lattice.next[2 * axis + 1][c];
        for (int ch = 0; ch < 3; ++ch) {
            if (up >= 0 && down >= 0) g[axis][ch] = 0.5 * (rho[up][ch] - rho[down][ch]);
            else if (up >= 0) g[axis][ch] = rho[up][ch] - rho[c][ch];
            else if (down >= 0) g[axis][ch] = rho[c][ch] - rho[down][ch];
        }
    }
    return g;
}

// One fused collision (Eq. 5) and streaming (Eq. 4) step from `f` into `g`; writes rho of `f` into
// `rho_out` when given. `rho_previous` (rho of the state before `f`) feeds the boundary's tangential
// correction when the lattice has one.
void step(const LbmLattice& lattice, const std::vector<double>& f, std::vector<double>& g,
          std::vector<std::array<double, 3>>* rho_out, const std::vector<std::array<double, 3>>* rho_previous) {
    const bool corrected = !lattice.tangent.empty() && rho_previous;
    const bool curved = !lattice.curvature_gain.empty() && rho_previous;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lattice.cell_count, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            const double* fc = f.data() + slot(c, 0);
            std::array<double, 3> rho{0, 0, 0};
            for (int i = 0; i < kLbmDirections; ++i)
                for (int ch = 0; ch < 3; ++ch) rho[ch] += fc[i * 3 + ch];
            if (rho_out) (*rho_out)[c] = rho;
            const std::array<double, 3>& keep = lattice.keep[c];
            std::array<double, 3> eq;
            for (int ch = 0; ch < 3; ++ch) eq[ch] = lattice.equilibrium[c][ch] * rho[ch] / kLbmDirections;
            for (int i = 0; i < kLbmDirections; ++i) {
                const int32_t to = lattice.next[i][c];
                if (to >= 0) {
                    double* out = g.data() + slot(static_cast<size_t>(to), i);
                    for (int ch = 0; ch < 3; ++ch) out[ch] = keep[ch] * fc[i * 3 + ch] + eq[ch];
                } else {
                    // Leaves through a boundary link: part of it is reflected back into this cell along
                    // the opposite direction, and the light entering through the link is added.
                    const size_t link = static_cast<size_t>(-to - 1);
                    double* out = g.data() + slot(c, i ^ 1);
                    std::array<double, 3> source = lattice.source[link];
                    if (corrected) {
                        const auto grad = gradient(lattice, *rho_previous, c);
                        const auto& t = lattice.tangent[link];
                        for (int ch = 0; ch < 3; ++ch)
                            source[ch] += lattice.tangent_gain[link][ch] *
                                          (t[0] * grad[0][ch] + t[1] * grad[1][ch] + t[2] * grad[2][ch]);
                    }
                    if (curved) {
                        const int32_t in1 = lattice.next[i ^ 1][c];
                        const int32_t in2 = in1 >= 0 ? lattice.next[i ^ 1][in1] : -1;
                        if (in2 >= 0) {
                            const auto& rp = *rho_previous;
                            for (int ch = 0; ch < 3; ++ch)
                                source[ch] += lattice.curvature_gain[link][ch] * (rp[c][ch] - 2 * rp[in1][ch] + rp[in2][ch]);
                        }
                    }
                    for (int ch = 0; ch < 3; ++ch)
                        out[ch] = lattice.reflection[link][ch] * (keep[ch] * fc[i * 3 + ch] + eq[ch]) + source[ch];
                }
            }
        }
    });
}

// Maxima and minima only, so the result does not depend on how TBB splits the range.
struct Change {
    double max_diff = 0, max_rho = 0, min_rho = 0, min_population = 0;
    bool finite = true;
};

// Between two consecutive rho (a then b), with f the populations that give b.
Change measure(const std::vector<std::array<double, 3>>& a, const std::vector<std::array<double, 3>>& b,
               const std::vector<double>& f) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, a.size(), kGrain), Change{},
        [&](const tbb::blocked_range<size_t>& r, Change acc) {
            for (size_t c = r.begin(); c != r.end(); ++c) {
                for (int ch = 0; ch < 3; ++ch) {
                    if (!std::isfinite(b[c][ch])) acc.finite = false;
                    acc.max_diff = std::max(acc.max_diff, std::abs(b[c][ch] - a[c][ch]));
                    acc.max_rho = std::max(acc.max_rho, std::abs(b[c][ch]));
                    acc.min_rho = std::min(acc.min_rho, b[c][ch]);
                }
                for (size_t k = slot(c, 0); k < slot(c + 1, 0); ++k) acc.min_population = std::min(acc.min_population, f[k]);
            }
            return acc;
        },
        [](Change x, const Change& y) {
            x.max_diff = std::max(x.max_diff, y.max_diff);
            x.max_rho = std::max(x.max_rho, y.max_rho);
            x.min_rho = std::min(x.min_rho, y.min_rho);
            x.min_population = std::min(x.min_population, y.min_population);
            x.finite = x.finite && y.finite;
            return x;
        });
}

}  // namespace

void validate_lattice(const LbmLattice& lattice) {
    const size_t n = lattice.cell_count;
    if (lattice.keep.size() != n || lattice.equilibrium.size() != n)
        throw InvalidArgumentError("lbm: collision coefficients for " + std::to_string(lattice.keep.size()) +
                                   " cells, lattice has " + std::to_string(n));
    if (lattice.reflection.size() != lattice.source.size())
        throw InvalidArgumentError("lbm: boundary links need one reflection and one source each");
    if (!lattice.tangent.empty() &&
        (lattice.tangent.size() != lattice.source.size() || lattice.tangent_gain.size() != lattice.source.size()))
        throw InvalidArgumentError("lbm: the tangential correction needs one tangent and one gain per boundary link");
    if (!lattice.curvature_gain.empty() && lattice.curvature_gain.size() != lattice.source.size())
        throw InvalidArgumentError("lbm: the curvature correction needs one gain per boundary link");
    const int64_t links = static_cast<int64_t>(lattice.reflection.size());
    for (int i = 0; i < kLbmDirections; ++i) {
        if (lattice.next[i].size() != n)
            throw InvalidArgumentError("lbm: neighbour list " + std::to_string(i) + " has the wrong size");
        for (int32_t to : lattice.next[i])
            if (to >= static_cast<int64_t>(n) || -static_cast<int64_t>(to) - 1 >= links)
                throw InvalidArgumentError("lbm: neighbour list " + std::to_string(i) + " names a cell or link that does not exist");
    }
}

LbmRun run_lattice_boltzmann(const LbmLattice& lattice, const LbmIterationOptions& options) {
    validate_lattice(lattice);
    if (!(options.tolerance > 0) || options.max_iterations < 1 || options.check_every < 2)
        throw InvalidArgumentError("lbm: the iteration needs tolerance > 0, max_iterations >= 1 and check_every >= 2");
    const size_t n = lattice.cell_count;
    std::vector<double> f(n * kLbmDirections * 3, 0.0), g(f.size(), 0.0);
    std::vector<std::array<double, 3>> rho0(n), rho1(n), rho_scratch;
    const bool corrected = !lattice.tangent.empty() || !lattice.curvature_gain.empty();
    if (corrected) rho_scratch.resize(n);

    LbmRun run;
    double previous_diff = -1;
    int previous_check = 0;
    int k = 0;
    while (k < options.max_iterations) {
        // check_every - 2 plain steps, then two that record rho: rho0 and rho1 are consecutive states.
        const int plain = std::min(options.check_every - 2, options.max_iterations - k - 2);
        // With a tangential correction every step records rho (the next step's gradients need it).
        for (int s = 0; s < plain; ++s, ++k) {
            if (corrected) {
                step(lattice, f, g, &rho_scratch, &rho1);
                rho_scratch.swap(rho1);
            } else {
                step(lattice, f, g, nullptr, nullptr);
            }
            f.swap(g);
        }
        step(lattice, f, g, &rho0, corrected ? &rho1 : nullptr);
        f.swap(g);
        step(lattice, f, g, &rho1, corrected ? &rho0 : nullptr);
        f.swap(g);
        k += 2;
        check_cancelled(options.progress);
        const Change c = measure(rho0, rho1, g);  // g holds the populations of rho1 after the swap
        run.iterations = k - 1;  // rho1 is the state after k - 1 steps
        run.min_rho = std::min(run.min_rho, c.min_rho);
        run.min_population = std::min(run.min_population, c.min_population);
        if (!c.finite || c.max_rho > options.divergence_limit) {
            run.diverged = true;
            break;
        }
        run.relative_change = c.max_rho > 0 ? c.max_diff / c.max_rho : 0;
        if (c.max_rho > 0 && previous_diff > 0) {
            // Contraction per step from the change at this check and at the previous one.
            const double lambda = std::pow(c.max_diff / previous_diff, 1.0 / static_cast<double>(k - previous_check));
            const double remaining = lambda < 1 ? c.max_diff * lambda / (1 - lambda) : std::numeric_limits<double>::infinity();
            if (remaining < options.tolerance * c.max_rho) {
                run.converged = true;
                break;
            }
            if (options.progress && lambda < 1) {
                // Fraction done, on a log scale of the remaining distance to the tolerance.
                const double done = std::log(options.tolerance * c.max_rho / remaining);
                options.progress->set_fraction(static_cast<float>(std::clamp(1.0 + done / 30.0, 0.0, 1.0)));
            }
        }
        if (c.max_diff == 0) {  // a fixed point (phi = 0 everywhere when no light enters)
            run.converged = true;
            break;
        }
        previous_diff = c.max_diff;
        previous_check = k;
    }
    run.rho = std::move(rho1);
    return run;
}

}  // namespace waxwork
