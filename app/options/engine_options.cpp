#include "app/options/engine_options.h"

#include "base/error.h"

#include <CLI/CLI.hpp>

namespace waxwork {

void add_engine_options(CLI::App& command, EngineOptions& options, const std::string& petsc_scope) {
    command
        .add_option("--engine", options.engine,
                    "cpu: solve in this process; petsc: solve " + petsc_scope +
                        " with the processes mpirun started (mpirun -n N waxwork ... --engine petsc; a build with PETSc)")
        ->check(CLI::IsMember({"cpu", "petsc"}))
        ->capture_default_str();
    command
        .add_option("--pc", options.pc, "--engine petsc: CG's preconditioner, boomeramg (hypre) or gamg (default boomeramg)")
        ->check(CLI::IsMember({"gamg", "boomeramg"}));
}

void check_engine_options(const EngineOptions& options) {
    if (options.petsc() && !kPetscBuilt) throw InvalidArgumentError("--engine petsc: " + petsc_unavailable_reason());
    if (!options.petsc() && options.pc) throw InvalidArgumentError("--pc applies only with --engine petsc");
}

#ifdef WAXWORK_HAVE_PETSC
PetscPeer chosen_preconditioner(const EngineOptions& options) {
    return options.pc.value_or("boomeramg") == "gamg" ? PetscPeer::CgGamg : PetscPeer::CgBoomerAmg;
}

const char* preconditioner_word(PetscPeer peer) { return peer == PetscPeer::CgGamg ? "gamg" : "boomeramg"; }
#endif

}  // namespace waxwork
