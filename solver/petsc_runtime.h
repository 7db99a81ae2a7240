// The process's PETSc runtime: PETSc (and through it MPI) initialised once, on first use, and finalised
// at exit. The single-process `waxwork` binary runs without mpirun: Open MPI then starts as a singleton
// (one rank); under `mpirun -n N` the N processes form PETSC_COMM_WORLD. When the program initialised
// PETSc itself, ensure_petsc_runtime() leaves it alone and does not finalise it.
//
// While Waxwork owns the runtime, PETSc's errors return their codes instead of printing a stack and
// aborting (the callers turn them into typed errors), and PETSc's signal handlers are removed so that a
// crash elsewhere in the program is reported as usual.
#pragma once

#ifdef WAXWORK_HAVE_PETSC

#include <cstdint>
#include <functional>
#include <vector>

namespace waxwork {

// Initialises PETSc with no arguments if nothing has, and registers its finalisation at exit. Thread
// safe; cheap after the first call. Throws AlgorithmError when PETSc or MPI cannot start.
void ensure_petsc_runtime();

// The same with the program's arguments, which PETSc reads its options from (as from the environment's
// PETSC_OPTIONS). They are kept for PETSc's lifetime. When PETSc already runs: as above.
void ensure_petsc_runtime(int argc, char** argv);

// A failed PETSc call (a non-zero code) as an AlgorithmError naming the call and PETSc's message.
void check_petsc(int code, const char* call);

// This process's rank and the number of processes in PETSC_COMM_WORLD (starts the runtime).
struct PetscProcesses {
    int rank = 0;
    int size = 1;
};
PetscProcesses petsc_processes();

// Runs `step` on every process of PETSC_COMM_WORLD (collectively: every process must call it, in the
// same order) and agrees on how it ended, so that no process goes on to a collective call that another
// will never make. When `step` threw on one or more processes, every process throws: the lowest failing
// rank rethrows its own exception, the others an Error with that rank's message and number (one message,
// whichever process prints it). Exceptions that are not std::exception are not caught.
void agreed_step(const std::function<void()>& step);

// Collective: rank 0's values on every process (resized there).
void broadcast_from_rank0(std::vector<double>& values);
void broadcast_from_rank0(std::vector<int32_t>& values);

// Collective: every process's value, in rank order, on every process.
std::vector<int64_t> gather_from_all(int64_t value);

}  // namespace waxwork

#endif
