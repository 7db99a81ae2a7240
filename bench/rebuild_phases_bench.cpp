// Every phase of the rebuild after a topological edit, timed on spot, with the bytes each phase must
// move: the roofline of docs/performance.md divides those bytes by memory_bandwidth_bench's bandwidth.
//
// "Must move" is the compulsory traffic: every array a phase reads, read once, and every array it
// writes, written once (sizes from the structures built, in bytes of their element types). Gathers
// through indices (a star's tets, a row's columns) are counted once, as if every cache line fetched
// were used in full, so the bound is optimistic for the phases that gather.
#include "bench_main.h"
#include "bench_meshes.h"
#include "multires/hierarchy.h"
#include "multires/multigrid_preconditioner.h"
#include "solver/diffusion_matrix.h"
#include "tetops/connectivity.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <vector>

namespace waxwork {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

template <typename T>
double bytes(const std::vector<T>& v) {
    return static_cast<double>(v.size() * sizeof(T));
}
double bytes(const CompressedRows& rows) { return bytes(rows.offsets) + bytes(rows.indices); }
double matrix_bytes(const std::vector<int32_t>& offsets, const std::vector<int32_t>& columns,
                    const std::vector<int32_t>& diagonal, const std::array<std::vector<double>, 3>& values) {
    return bytes(offsets) + bytes(columns) + bytes(diagonal) + bytes(values[0]) + bytes(values[1]) + bytes(values[2]);
}
double level_bytes(const HierarchyLevel& level) {
    return bytes(level.original_vertex) + bytes(level.parent_vertex) + bytes(level.graph) +
           matrix_bytes(level.offsets, level.columns, level.diagonal, level.values) +
           bytes(level.interpolation.offsets) + bytes(level.interpolation.columns) + bytes(level.interpolation.weights);
}

// Megabytes each phase must move on this mesh (see the file comment).
struct PhaseBytes {
    double vertex_tets, tet_neighbors, one_rings, boundary, components;
    double pattern, geometry, values, hierarchy, multigrid;
};

PhaseBytes phase_bytes(const TetMesh& mesh, const std::vector<TetMaterial>& materials, const TetConnectivity& c,
                       const DiffusionMatrix& m, const MultiresHierarchy& h, const MultigridPreconditioner& mg) {
    PhaseBytes b{};
    const double tets = bytes(mesh.tets), positions = bytes(mesh.positions);
    // Read the tets, write the rows.
    b.vertex_tets = tets + bytes(c.vertex_tets);
    // Read the stars and the tets, write the neighbours.
    b.tet_neighbors = bytes(c.vertex_tets) + tets + bytes(c.tet_neighbors);
    // Read the stars and the tets, write the one-rings and the edges.
    b.one_rings = bytes(c.vertex_tets) + tets + bytes(c.vertex_vertices) + bytes(c.edges);
    // Read the neighbours, write the faces, the flags and the boundary vertices.
    b.boundary = bytes(c.tet_neighbors) + bytes(c.boundary_faces) + bytes(c.is_boundary_vertex) + bytes(c.boundary_vertices);
    // Read the neighbours, write the labels.
    b.components = bytes(c.tet_neighbors) + bytes(c.tet_component);
    // Read the one-rings, stars, tets and boundary faces; write offsets, columns, diagonal and incidences.
    b.pattern = bytes(c.vertex_vertices) + bytes(c.vertex_tets) + tets + bytes(c.boundary_faces) + bytes(m.offsets) +
                bytes(m.columns) + bytes(m.diagonal) + bytes(m.tet_incidences) + bytes(m.vertex_face_offsets) +
                bytes(m.vertex_faces) + bytes(m.vertex_face_slots);
    // Read positions and tets, write the tets' geometry and the faces' areas.
    b.geometry = positions + tets + bytes(m.tet_geometry) + bytes(m.boundary_face_area);
    // Read materials, incidences, stars, geometry, coefficients and face data; write coefficients,
    // three channels of values and the source.
    b.values = bytes(materials) +
               bytes(m.tet_incidences) + bytes(c.vertex_tets) + bytes(m.tet_geometry) + 2 * bytes(m.tet_coefficients) +
               bytes(m.vertex_faces) + bytes(m.vertex_face_slots) + bytes(m.boundary_face_area) +
               3 * bytes(m.values[0]) + bytes(m.source);
    // Every level written once and read once (level 0 from the matrix, the others to build the next).
    for (const HierarchyLevel& level : h.levels) b.hierarchy += 2 * level_bytes(level);
    // Every Galerkin operator (three channels in double, columns) written once and read once, and every
    // interpolation operator read twice (P and its transpose).
    for (size_t l = 1; l < mg.level_count(); ++l)
        b.multigrid += 2 * (static_cast<double>(mg.nonzeros(l)) * (3 * sizeof(double) + sizeof(int32_t)) +
                            static_cast<double>(mg.rows(l)) * 2 * sizeof(int32_t));
    for (size_t l = 0; l + 1 < h.levels.size(); ++l) {
        const InterpolationOperator& p = h.levels[l].interpolation;
        b.multigrid += 2 * (bytes(p.offsets) + bytes(p.columns) + bytes(p.weights));
    }
    return b;
}

// One rebuild per iteration, phase by phase, on spot lit as the other benches light it. The counters
// are the last iteration's milliseconds per phase and the megabytes each must move; with
// --benchmark_repetitions their medians are the roofline table's measured column.
void BM_RebuildPhases(benchmark::State& state) {
    const bench::LitSpot& lit = bench::lit_spot(static_cast<size_t>(state.range(0)));
    const TetMesh& mesh = lit.mesh;
    AssemblyOptions assembly;
    assembly.mm_per_unit = lit.mm_per_unit;
    ConnectivityBuildTimes ct;
    double pattern_ms = 0, matrix_ms = 0, values_ms = 0, hierarchy_ms = 0, multigrid_ms = 0;
    PhaseBytes b{};
    for (auto _ : state) {
        const TetConnectivity c = build_connectivity(mesh, &ct);
        auto start = Clock::now();
        const DiffusionMatrix pattern = assemble_diffusion_pattern(mesh, c, assembly);
        pattern_ms = ms_since(start);
        start = Clock::now();
        DiffusionMatrix m = assemble_diffusion_matrix(mesh, c, lit.materials, assembly);
        matrix_ms = ms_since(start);
        start = Clock::now();
        assemble_diffusion_values(m, c, lit.materials);
        values_ms = ms_since(start);
        start = Clock::now();
        const MultiresHierarchy h = build_multires_hierarchy(m, mesh.positions);
        hierarchy_ms = ms_since(start);
        start = Clock::now();
        const MultigridPreconditioner mg(h);
        multigrid_ms = ms_since(start);
        b = phase_bytes(mesh, lit.materials, c, m, h, mg);
    }
    const auto counter = [&](const char* name, double value) { state.counters[name] = value; };
    counter("vertex_tets_ms", ct.vertex_tets);
    counter("neighbors_ms", ct.tet_neighbors);
    counter("one_rings_ms", ct.one_rings);
    counter("boundary_ms", ct.boundary);
    counter("components_ms", ct.components);
    counter("connectivity_ms", ct.vertex_tets + ct.tet_neighbors + ct.one_rings + ct.boundary + ct.components);
    counter("pattern_ms", pattern_ms);
    counter("matrix_ms", matrix_ms);  // pattern, geometry and values
    counter("values_ms", values_ms);
    counter("hierarchy_ms", hierarchy_ms);
    counter("multigrid_ms", multigrid_ms);
    counter("vertex_tets_MB", b.vertex_tets / 1e6);
    counter("neighbors_MB", b.tet_neighbors / 1e6);
    counter("one_rings_MB", b.one_rings / 1e6);
    counter("boundary_MB", b.boundary / 1e6);
    counter("components_MB", b.components / 1e6);
    counter("pattern_MB", b.pattern / 1e6);
    counter("geometry_MB", b.geometry / 1e6);
    counter("values_MB", b.values / 1e6);
    counter("hierarchy_MB", b.hierarchy / 1e6);
    counter("multigrid_MB", b.multigrid / 1e6);
    counter("tets", static_cast<double>(mesh.tet_count()));
}
BENCHMARK(BM_RebuildPhases)->Arg(500'000)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
}  // namespace waxwork

WAXWORK_BENCHMARK_MAIN()
