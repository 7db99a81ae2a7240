// `mpirun -n N waxwork run SESSION -o OUTDIR --engine petsc`: a session whose steps are converged renders,
// saves, lights and cameras (no edits, no live frames), every render solved by the processes together
// (render/distributed_render.h) and drawn by rank 0 as run_session draws it, from the session's material,
// lights, camera, image size, tolerance, crease angle and scale. Every process loads the input; a
// surface input is meshed by every process, and they refuse to go on unless they got the same volume.
//
// Exists only in builds with PETSc (WAXWORK_HAVE_PETSC).
#pragma once

#ifdef WAXWORK_HAVE_PETSC

#include "scene/session.h"
#include "solver/petsc_peers.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace waxwork {

struct DistributedSessionResult {
    int rank = 0;
    int processes = 1;
    double load_ms = 0;
    size_t input_tets = 0;
    std::vector<StepMetrics> steps;
    std::vector<std::filesystem::path> written;  // rank 0's files, in order
    int64_t edges = 0, edge_cut = 0;              // of the partition (the volume does not change)
};

// Collective over PETSC_COMM_WORLD: every process passes the same session and folder. Errors are agreed
// (petsc_runtime.h) and name the session and the step as run_session's do; InvalidArgumentError for a
// step other than the above.
DistributedSessionResult run_session_distributed(const Session& session, const std::filesystem::path& output_directory,
                                                 PetscPeer preconditioner);

}  // namespace waxwork

#endif  // WAXWORK_HAVE_PETSC
