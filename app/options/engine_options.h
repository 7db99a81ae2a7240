// --engine cpu|petsc and --pc boomeramg|gamg, shared by `render` and `run`: whether this process solves
// alone or with the processes mpirun started (render/distributed_render.h), and CG's preconditioner then.
#pragma once

#include "solver/petsc_peers.h"

#include <optional>
#include <string>

namespace CLI {
class App;
}

namespace waxwork {

struct EngineOptions {
    std::string engine = "cpu";
    std::optional<std::string> pc;  // nullopt: boomeramg
    bool petsc() const { return engine == "petsc"; }
};

// Registers the options; `petsc_scope` says what --engine petsc solves in this command.
void add_engine_options(CLI::App& command, EngineOptions& options, const std::string& petsc_scope);

// Throws InvalidArgumentError for --engine petsc in a build without PETSc and for --pc without it.
void check_engine_options(const EngineOptions& options);

#ifdef WAXWORK_HAVE_PETSC
// The preconditioner --pc names.
PetscPeer chosen_preconditioner(const EngineOptions& options);
// "boomeramg" or "gamg", as --pc spells it.
const char* preconditioner_word(PetscPeer peer);
#endif

}  // namespace waxwork
