#include "render/distributed_render.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/material.h"
#include "solver/petsc_runtime.h"
#include "solver/solved_scene.h"
#include "tetops/connectivity.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <utility>

namespace waxwork {
namespace {

// q and the corners' light as flat arrays, for the broadcast from rank 0.
struct SceneLight {
    std::vector<double> q;                 // 3 per vertex
    std::vector<int32_t> corner_indices;   // 5 per corner: tet, local face, the three vertices
    std::vector<double> corner_delta;      // 3 per corner

    std::vector<std::array<double, 3>> vertex_q() const {
        std::vector<std::array<double, 3>> out(q.size() / 3);
        for (size_t v = 0; v < out.size(); ++v) out[v] = {q[3 * v], q[3 * v + 1], q[3 * v + 2]};
        return out;
    }
    std::vector<PortableCornerLight> corners() const {
        std::vector<PortableCornerLight> out(corner_delta.size() / 3);
        for (size_t k = 0; k < out.size(); ++k) {
            const int32_t* i = corner_indices.data() + 5 * k;
            out[k] = {i[0], i[1], {i[2], i[3], i[4]}, {corner_delta[3 * k], corner_delta[3 * k + 1], corner_delta[3 * k + 2]}};
        }
        return out;
    }
};

SceneLight flatten(const LitScene& lit, const TetConnectivity& connectivity) {
    SceneLight light;
    light.q.reserve(3 * lit.scene.q.size());
    for (const Rgb& q : lit.scene.q) light.q.insert(light.q.end(), q.begin(), q.end());
    for (const CornerLight& corner : lit.corners) {
        const BoundaryFace& face = connectivity.boundary_faces[corner.face];
        light.corner_indices.insert(light.corner_indices.end(), {face.tet, face.local_face, corner.vertices[0],
                                                                 corner.vertices[1], corner.vertices[2]});
        light.corner_delta.insert(light.corner_delta.end(), corner.delta.begin(), corner.delta.end());
    }
    return light;
}

}  // namespace

DistributedRender render_volume_distributed(const TetMesh& mesh, const std::string& volume_name,
                                            const VolumeRenderSettings& settings, PetscPeer preconditioner) {
    DistributedRender result;
    const PetscProcesses processes = petsc_processes();
    result.rank = processes.rank;
    result.processes = processes.size;
    const bool root = processes.rank == 0;

    RowRange range;
    agreed_step([&] {
        if (mesh.tet_count() == 0) throw InvalidArgumentError(volume_name + ": the volume has no tets to render");
        if (settings.diffusion.backend != SolverBackend::Cpu)
            throw InvalidArgumentError("--engine petsc solves on the CPU: it cannot take --backend gpu");
        if (settings.alternative)
            throw InvalidArgumentError("--engine petsc solves TransCut's or FEM's system: the seeds' methods "
                                       "(--method fd, lbm, ...) run only with --engine cpu");
        range = naming_context(volume_name, [&] { return balanced_row_range(mesh.vertex_count(), processes.size, processes.rank); });
    });

    // Rank 0 lights the surface; everyone needs the materials of its tets.
    std::vector<TetMaterial> materials;
    std::optional<TetConnectivity> connectivity;
    std::optional<LitScene> lit;
    SceneLight light;
    agreed_step([&] {
        materials = naming_context(volume_name, [&] { return resolve_materials(mesh, settings.material); });
        if (!root) return;
        connectivity.emplace(build_connectivity(mesh));
        lit.emplace(light_scene(mesh, *connectivity, materials, settings.lighting, settings.crease_angle_degrees));
        light = flatten(*lit, *connectivity);
    });
    broadcast_from_rank0(light.q);
    broadcast_from_rank0(light.corner_indices);
    broadcast_from_rank0(light.corner_delta);

    OwnedRows rows;
    double assembly_ms = 0;
    agreed_step([&] {
        const auto start = std::chrono::steady_clock::now();
        AssemblyOptions assembly;
        assembly.discretization = settings.diffusion.discretization;
        assembly.stiffness_form = settings.diffusion.stiffness_form;
        assembly.mm_per_unit = settings.diffusion.mm_per_unit;
        const std::vector<PortableCornerLight> corners = light.corners();
        rows = assemble_owned_rows(mesh, materials, light.vertex_q(), corners, range, assembly);
        assembly_ms = milliseconds_since(start);
    });
    std::vector<double>().swap(light.q);
    const EdgeCount count = owned_edge_count(rows);
    const std::vector<int64_t> edges = gather_from_all(count.edges), cut = gather_from_all(count.cut);
    for (size_t p = 0; p < edges.size(); ++p) {
        result.edges += edges[p];
        result.edge_cut += cut[p];
    }
    result.rows_per_process = gather_from_all(range.size());
    result.tets_per_process = gather_from_all(static_cast<int64_t>(rows.local_tets));
    const std::vector<int64_t> assembly_us = gather_from_all(static_cast<int64_t>(assembly_ms * 1000));
    result.assembly_ms = static_cast<double>(*std::max_element(assembly_us.begin(), assembly_us.end())) / 1000;

    std::vector<std::array<double, 3>> phi;
    agreed_step([&] {
        DistributedSolveOptions options;
        options.preconditioner = preconditioner;
        options.relative_tolerance = settings.diffusion.relative_tolerance;
        options.max_iterations = settings.diffusion.max_iterations;
        phi = solve_distributed(rows, mesh.vertex_count(), options, result.solve);
    });
    rows = {};

    agreed_step([&] {
        if (!root) return;
        SolvedScene scene = std::move(lit->scene);
        DiffusionSolution& diffusion = scene.diffusion;
        diffusion.phi = std::move(phi);
        diffusion.iterations = result.solve.iterations;
        diffusion.estimated_relative_error = result.solve.estimated_relative_error;
        diffusion.assembly_ms = result.assembly_ms + result.solve.conversion_ms;
        diffusion.solve_ms = result.solve.preconditioner_ms + result.solve.solve_ms + result.solve.gather_ms;
        diffusion.backend = SolverBackend::Cpu;
        shade_scene(scene);
        result.render = render_volume_light(mesh, VolumeLight{std::move(*connectivity), std::move(materials), std::move(scene)},
                                            settings);
    });
    return result;
}

}  // namespace waxwork
