#include "solver/methods/alternative_method.h"

#include "base/error.h"
#include "solver/methods/dipole.h"
#include "solver/methods/fd.h"
#include "solver/methods/fvm.h"
#include "solver/methods/lbm.h"

#include <array>
#include <cmath>

namespace waxwork {
namespace {

struct NamedMethod {
    AlternativeMethod method;
    const char* name;
};

constexpr std::array<NamedMethod, 6> kMethods = {{
    {AlternativeMethod::FdJacobi, "fd"},
    {AlternativeMethod::FdCg, "fd-cg"},
    {AlternativeMethod::FvmRelax, "fvm"},
    {AlternativeMethod::FvmCg, "fvm-cg"},
    {AlternativeMethod::Lbm, "lbm"},
    {AlternativeMethod::Dipole, "dipole"},
}};

}  // namespace

const char* alternative_method_name(AlternativeMethod method) {
    for (const NamedMethod& m : kMethods)
        if (m.method == method) return m.name;
    return "unknown";
}

std::vector<AlternativeMethod> all_alternative_methods() {
    std::vector<AlternativeMethod> methods;
    for (const NamedMethod& m : kMethods) methods.push_back(m.method);
    return methods;
}

std::optional<AlternativeMethod> parse_alternative_method(std::string_view name) {
    for (const NamedMethod& m : kMethods)
        if (name == m.name) return m.method;
    return std::nullopt;
}

bool uses_voxel_grid(AlternativeMethod method) {
    return method == AlternativeMethod::FdJacobi || method == AlternativeMethod::FdCg || method == AlternativeMethod::Lbm;
}

double default_cell_mm(const MethodProblem& problem) {
    const double volume_mm3 = total_volume(problem.mesh) * std::pow(problem.mm_per_unit, 3);
    const double vertices = static_cast<double>(std::max<size_t>(1, problem.mesh.vertex_count()));
    return std::cbrt(volume_mm3 / vertices);
}

MethodSolution solve_alternative(const MethodProblem& problem, const AlternativeMethodSettings& settings) {
    const std::string name = alternative_method_name(settings.method);
    if (!(settings.cell_mm >= 0 && std::isfinite(settings.cell_mm)))
        throw InvalidArgumentError(name + ": the cell size must be a positive number of mm (got " +
                                   std::to_string(settings.cell_mm) + ")");
    if (!(settings.relative_tolerance > 0 && settings.relative_tolerance < 1))
        throw InvalidArgumentError(name + ": the tolerance must be in (0, 1) (got " +
                                   std::to_string(settings.relative_tolerance) + ")");
    const double cell_mm = settings.cell_mm > 0 ? settings.cell_mm : default_cell_mm(problem);
    switch (settings.method) {
        case AlternativeMethod::FdJacobi:
        case AlternativeMethod::FdCg: {
            FdOptions options;
            options.cell_size_mm = cell_mm;
            options.solver = settings.method == AlternativeMethod::FdCg ? FdSolver::Cg : FdSolver::Jacobi;
            options.relative_tolerance = settings.relative_tolerance;
            return solve_fd(problem, options);
        }
        case AlternativeMethod::FvmRelax:
        case AlternativeMethod::FvmCg: {
            FvmOptions options;
            options.solver = settings.method == AlternativeMethod::FvmCg ? FvmSolver::Cg : FvmSolver::Relaxation;
            options.relative_tolerance = settings.relative_tolerance;
            return solve_fvm(problem, options);
        }
        case AlternativeMethod::Lbm: {
            LbmOptions options;
            options.cell_size_mm = cell_mm;
            options.tolerance = settings.relative_tolerance;
            return solve_lbm(problem, options);
        }
        case AlternativeMethod::Dipole:
            return solve_dipole(problem, DipoleOptions{});
    }
    throw InvalidArgumentError("unknown alternative method");
}

}  // namespace waxwork
