// One call from a volume, its materials and the incident light to the fluence phi at every vertex:
// the path `waxwork render` and the tests take. Finer control (keeping matrices between frames,
// choosing solvers) is in diffusion_matrix.h and conjugate_gradient.h.
#pragma once

#include "gl/gl_context.h"
#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

enum class SolverPrecision {
    // The safe default: double CG converges on meshes with slivers (TransCut's cotangent weights reach
    // 1e4-1e6 there) and to tolerances well below 1e-4, where float stalls at its rounding floor.
    Double,
    // About 1.5x faster per iteration (half the matrix bandwidth); accurate to ~1e-4 on good meshes.
    // Reports AlgorithmError rather than a wrong answer when it cannot reach the tolerance.
    Float,
};

enum class SolverBackend {
    Cpu,
    // Jacobi CG in float on OpenGL 4.3 compute shaders (solver/gpu/gpu_conjugate_gradient.h), on the
    // context of DiffusionOptions::gl. Falls back to the CPU when the GPU path cannot run, and
    // finishes in double on the CPU, from the GPU's phi, when float CG stops short of the tolerance
    // (see DiffusionSolution::gpu_fallback_reason); `precision` does not apply (always float).
    Gpu,
};

struct DiffusionOptions {
    Discretization discretization = Discretization::TransCut;
    StiffnessForm stiffness_form = StiffnessForm::Gradient;
    SolverPrecision precision = SolverPrecision::Double;
    double mm_per_unit = 1.0;          // model units to millimetres (coefficients are per mm)
    double relative_tolerance = 1e-3;  // stopping rule: estimated relative error of phi (D-norm, see
                                       // conjugate_gradient.h)
    int max_iterations = 10000;
    SolverBackend backend = SolverBackend::Cpu;
    const GlApi* gl = nullptr;  // Gpu: the entry points of a current OpenGL context (e.g. HeadlessGlContext)
};

struct DiffusionSolution {
    // Per vertex, per rgb channel: the fluence phi (zero at vertices of no tet).
    std::vector<std::array<double, 3>> phi;
    std::array<int, 3> iterations{};
    std::array<double, 3> estimated_relative_error{};
    double assembly_ms = 0;
    double solve_ms = 0;
    SolverBackend backend = SolverBackend::Cpu;  // the backend that produced phi
    // Backend Gpu requested but the CPU solved: why (no OpenGL 4.3, a shader that failed to compile with
    // the driver's log, ...); empty otherwise. Callers print it as a warning.
    std::string gpu_fallback_reason;
};

// q: per vertex (volume vertex order), per channel, the diffuse incoming light (only boundary vertices
// are read); `corners`: where faces at a crease receive other light than their vertex's q
// (shading_surface.h: corner_light), added to b = source * q. materials: one per tet. Throws
// InvalidArgumentError for invalid coefficients or sizes and AlgorithmError if the solver breaks down or
// fails to converge to the tolerance.
DiffusionSolution solve_diffusion(const TetMesh& mesh, const TetConnectivity& connectivity,
                                  const std::vector<TetMaterial>& materials,
                                  const std::vector<std::array<double, 3>>& q, const DiffusionOptions& options,
                                  std::span<const CornerLight> corners = {});

// Solves an assembled system (all three channels) with Jacobi CG; phi is the warm start and result
// (resized and zeroed if its size is wrong). Fills iterations, errors, solve_ms, backend and
// gpu_fallback_reason of `solution`.
void solve_diffusion_system(const DiffusionMatrix& matrix, const std::vector<std::array<double, 3>>& q,
                            const DiffusionOptions& options, DiffusionSolution& solution,
                            std::span<const CornerLight> corners = {});

}  // namespace waxwork
