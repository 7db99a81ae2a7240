// The process's PETSc runtime: PETSc (and through it MPI) initialised once, on first use, and finalised
// at exit. The single-process `waxwork` binary runs without mpirun: Open MPI then starts as a singleton
// (one rank). When the program initialised PETSc itself (a future `mpirun` entry point passing argc and
// argv), ensure_petsc_runtime() leaves it alone and does not finalise it.
//
// While Waxwork owns the runtime, PETSc's errors return their codes instead of printing a stack and
// aborting (the callers turn them into typed errors), and PETSc's signal handlers are removed so that a
// crash elsewhere in the program is reported as usual.
#pragma once

#ifdef WAXWORK_HAVE_PETSC

namespace waxwork {

// Initialises PETSc with no arguments if nothing has, and registers its finalisation at exit. Thread
// safe; cheap after the first call. Throws AlgorithmError when PETSc or MPI cannot start.
void ensure_petsc_runtime();

}  // namespace waxwork

#endif
