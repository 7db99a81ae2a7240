// The TransCut matrix values (Li et al. 2013, Eqs. 10-14; or the FEM variant) assembled on the device,
// straight into a GpuMatrix's value buffer, so a material or geometry change never round-trips the
// matrix through the host. The host keeps what depends on topology only (the pattern and the slots of
// each tet and boundary face in its vertices' rows, assemble_diffusion_pattern), and each tet's
// material coefficients (a few numbers per tet, validated on the host).
//
// One invocation per row gathers the contributions of the tets and boundary faces around its vertex,
// recomputing each tet's stiffness from the positions in double (Eq. 10 in the gradient form of the
// paper's appendix, relative to the tet's first vertex, as the CPU path does), accumulates the row in
// double and stores it in float. Gathering per row, like the CPU's assemble_row, needs no atomics
// (float atomics are an extension OpenGL 4.3 lacks) and makes the result deterministic. Recomputing a
// tet's geometry in each of its four rows costs more arithmetic than storing it, but a stored copy
// (7 doubles per tet) would be another 28 MB to keep at 500K tets, and arithmetic is what GPUs have.
//
// Not on the device: the source operator of the right-hand side (Eq. 12): lights are set from q on the
// host (GpuDiffusionSolver::set_light), and the cotangent form (the gradient form is the default and
// the one the float analysis recommends, diffusion_matrix.h).
#pragma once

#include "gl/gpu_compute.h"
#include "solver/diffusion_matrix.h"
#include "solver/gpu/gpu_matrix.h"

#include <span>
#include <vector>

namespace waxwork {

class GpuMatrixAssembly {
public:
    // Uploads the topology of `pattern` (assemble_diffusion_pattern, or a full DiffusionMatrix of the
    // same mesh) for matrices stored with `layout`, and the positions of `mesh`. Compiles the kernel.
    // Throws InvalidArgumentError for the cotangent stiffness form or sizes that do not match, GpuError
    // when the driver cannot run it. The context of `gl` must stay current while this object lives.
    GpuMatrixAssembly(const GlApi& gl, const TetMesh& mesh, const TetConnectivity& connectivity,
                      const DiffusionMatrix& pattern, const GpuMatrixLayout& layout);
    ~GpuMatrixAssembly();
    GpuMatrixAssembly(const GpuMatrixAssembly&) = delete;
    GpuMatrixAssembly& operator=(const GpuMatrixAssembly&) = delete;

    // New positions of the same topology (relaxation); the next assemble() uses them.
    void set_positions(const TetMesh& mesh);

    // Every tet's coefficients from `materials` (validated: InvalidArgumentError names the first bad
    // tet), then every row into target.values. Throws InvalidMeshError naming a tet of non-positive
    // volume (the values are then not usable).
    void assemble(const std::vector<TetMaterial>& materials, GpuMatrix& target);

    // After the materials of `changed_tets` changed: uploads only their coefficients and re-assembles
    // only the rows of their vertices. Returns those rows, ascending (as update_diffusion_matrix).
    // `mesh` is the mesh of the constructor (its tets name the rows).
    std::vector<int32_t> update(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                                std::span<const int32_t> changed_tets, GpuMatrix& target);

    size_t rows() const { return rows_; }

private:
    // Assembles `count` rows: all rows when `row_list` is null, else the rows it lists.
    void run(GpuMatrix& target, size_t count, const GpuBuffer* row_list);
    void upload_coefficients(const std::vector<TetMaterial>& materials, std::span<const int32_t> which);

    const GlApi* gl_;
    size_t rows_ = 0, tets_ = 0;
    bool fem_ = false;
    double mm_per_unit_ = 1;
    ComputeProgram program_;
    // The topology's int arrays in one buffer (sections: see the kernel), read-only after construction.
    GpuBuffer topology_;
    GpuBuffer positions_;     // double xyz per vertex (model units)
    GpuBuffer coefficients_;  // per tet: kappa rgb, mu_a rgb, 1/A, 1/(A (1 - F_dr)), float
    GpuBuffer scratch_;       // double per CSR entry and channel: the rows being accumulated
    GpuBuffer params_;        // mm_per_unit (double) and the first tet of non-positive volume (int)
};

}  // namespace waxwork
