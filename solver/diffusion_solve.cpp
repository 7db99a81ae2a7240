#include "solver/diffusion_solve.h"

#include "solver/conjugate_gradient.h"
#include "tetops/error.h"

#include <chrono>
#include <cmath>
#include <sstream>

namespace waxwork {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <typename Scalar>
ConjugateGradientResult solve_channel(const DiffusionMatrix& m, const std::vector<double>& b, int channel,
                                      const DiffusionOptions& options, std::vector<std::array<double, 3>>& phi) {
    const size_t n = m.size();
    std::vector<Scalar> values(m.values[channel].begin(), m.values[channel].end());
    std::vector<Scalar> rhs(b.begin(), b.end());
    std::vector<Scalar> x(n);
    for (size_t i = 0; i < n; ++i) x[i] = static_cast<Scalar>(phi[i][channel]);
    const CsrMatrixView<Scalar> view{n, m.offsets.data(), m.columns.data(), values.data()};
    ConjugateGradientOptions cg;
    cg.relative_tolerance = options.relative_tolerance;
    cg.max_iterations = options.max_iterations;
    const ConjugateGradientResult result = solve_jacobi_cg<Scalar>(view, rhs, x, cg);
    for (size_t i = 0; i < n; ++i) phi[i][channel] = x[i];
    return result;
}

}  // namespace

void solve_diffusion_system(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q,
                            const DiffusionOptions& options, DiffusionSolution& solution) {
    const auto start = std::chrono::steady_clock::now();
    const size_t n = matrix.size();
    if (solution.phi.size() != n) solution.phi.assign(n, {0.0, 0.0, 0.0});
    for (const auto& v : q)
        for (double c : v)
            if (!std::isfinite(c)) throw InvalidArgumentError("solve_diffusion: the incident light q is not finite");
    std::vector<double> b(n);
    for (int c = 0; c < 3; ++c) {
        diffusion_right_hand_side(matrix, q, c, b);
        const ConjugateGradientResult r = options.precision == SolverPrecision::Float
                                              ? solve_channel<float>(matrix, b, c, options, solution.phi)
                                              : solve_channel<double>(matrix, b, c, options, solution.phi);
        solution.iterations[c] = r.iterations;
        solution.estimated_relative_error[c] = r.estimated_relative_error;
        if (!r.converged) {
            std::ostringstream msg;
            msg << "solve_diffusion: channel " << "rgb"[c] << " did not converge to relative error "
                << options.relative_tolerance << " (" << r.iterations << " iterations, estimated error "
                << r.estimated_relative_error << ", "
                << (options.precision == SolverPrecision::Float ? "float: try double precision or "
                                                                 : "")
                << "check the mesh for slivers)";
            throw AlgorithmError(msg.str());
        }
    }
    solution.solve_ms = ms_since(start);
}

DiffusionSolution solve_diffusion(const TetMesh& mesh, const TetConnectivity& connectivity,
                                  const std::vector<TetMaterial>& materials,
                                  const std::vector<std::array<double, 3>>& q, const DiffusionOptions& options) {
    if (q.size() != mesh.vertex_count())
        throw InvalidArgumentError("solve_diffusion: " + std::to_string(q.size()) + " light values for " +
                                   std::to_string(mesh.vertex_count()) + " vertices");
    DiffusionSolution solution;
    const auto start = std::chrono::steady_clock::now();
    AssemblyOptions assembly;
    assembly.discretization = options.discretization;
    assembly.stiffness_form = options.stiffness_form;
    assembly.mm_per_unit = options.mm_per_unit;
    const DiffusionMatrix matrix = assemble_diffusion_matrix(mesh, connectivity, materials, assembly);
    solution.assembly_ms = ms_since(start);
    solve_diffusion_system(matrix, q, options, solution);
    return solution;
}

}  // namespace waxwork
