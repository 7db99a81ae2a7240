// The command line: `waxwork SUBCOMMAND ...`. Exit status 0 on success; on failure a single line
// "waxwork: MESSAGE" on stderr and a non-zero status (1 for errors in the work, 2 for usage errors).
#pragma once

namespace waxwork {

// Under mpirun (--engine petsc) every process runs the command and meets the same errors (the
// distributed render agrees on them); only rank 0 prints the message, so it appears once.
int run_cli(int argc, char** argv);

// The arguments run_cli was called with (PETSc's initialisation reads its options from them).
struct ProgramArguments {
    int argc = 0;
    char** argv = nullptr;
};
ProgramArguments program_arguments();

}  // namespace waxwork
