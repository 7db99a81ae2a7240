// One picture of a volume with the diffusion solved by several processes (`mpirun -n N waxwork render
// ... --engine petsc`): the rows of the system split by contiguous vertex ranges of the mesh's (Morton)
// order (solver/owned_rows.h), each process assembling its own rows from the tets around them, PETSc
// solving (solver/petsc_distributed_solve.h), and rank 0 lighting the surface before and drawing the
// image after exactly as render_volume does.
//
// Every process holds the whole mesh (it reads the whole file): the lighting, the shading and the
// drawing need the boundary surface, which only rank 0 builds, while the others keep only the mesh
// and their rows' share of the system. Rank 0 computes q and the crease corners' light and broadcasts
// them; each process builds its right-hand side from its own rows' coefficients.
//
// Exists only in builds with PETSc (WAXWORK_HAVE_PETSC).
#pragma once

#ifdef WAXWORK_HAVE_PETSC

#include "render/volume_render.h"
#include "solver/owned_rows.h"
#include "solver/petsc_distributed_solve.h"

#include <cstdint>
#include <string>
#include <vector>

namespace waxwork {

struct DistributedRender {
    VolumeRender render;  // on rank 0: what render_volume gives; empty on the other processes
    int rank = 0;
    int processes = 1;
    // The partition: rows (vertices) and assembled tets per process, and the edges of the mesh, those
    // whose two ends are owned by different processes counted in edge_cut.
    std::vector<int64_t> rows_per_process, tets_per_process;
    int64_t edges = 0;
    int64_t edge_cut = 0;
    double assembly_ms = 0;  // the slowest process's assembly of its rows
    DistributedSolveReport solve;
};

// Collective over PETSC_COMM_WORLD: every process passes the same mesh, name and settings. Errors are
// agreed (petsc_runtime.h: agreed_step): every process throws, and rank 0's message is the lowest
// failing rank's. Throws InvalidArgumentError for an empty volume, more processes than vertices, a GPU
// backend or an alternative method (the distributed solve is TransCut's or FEM's system on the CPU), and
// what render_volume and solve_distributed throw.
DistributedRender render_volume_distributed(const TetMesh& mesh, const std::string& volume_name,
                                            const VolumeRenderSettings& settings, PetscPeer preconditioner);

}  // namespace waxwork

#endif  // WAXWORK_HAVE_PETSC
