#include "solver/gpu/gpu_assembly.h"

#include "base/error.h"

#include <algorithm>
#include <climits>
#include <string>

namespace waxwork {
namespace {

// The topology travels in one int buffer with its sections at the offsets given as uniforms: OpenGL
// 4.3 promises only 8 storage blocks per compute shader, and the assembly reads eleven arrays.
// Sections: tets (4 per tet), row offsets, diagonal positions, stored positions of the CSR entries,
// vertex_tets offsets and indices, incidences (local index + 3 slots), vertex_face offsets, faces and
// slots (2 per incidence), boundary faces (3 vertices + owning tet).
constexpr const char* kAssembleRows = R"(#version 430
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Topology { int topo[]; };
layout(std430, binding = 1) readonly buffer Positions { double positions[]; };
layout(std430, binding = 2) readonly buffer Coefficients { float coefficients[]; };
layout(std430, binding = 3) buffer Scratch { double scratch[]; };
layout(std430, binding = 4) buffer Params { double mm_per_unit; int bad_tet; };
layout(std430, binding = 5) readonly buffer RowList { int row_list[]; };
layout(std430, binding = 6) buffer Values { float values[]; };
uniform uint n;
uniform uint use_list;
uniform uint fem;
uniform uint o_tets, o_row_offsets, o_diagonal, o_stored, o_vt_offsets, o_vt, o_inc, o_vf_offsets, o_vf,
    o_vf_slots, o_faces;

// For local vertex a, the other three in ascending order (DiffusionMatrix::TetIncidence::slots).
const int kOthers[12] = int[12](1, 2, 3, 0, 2, 3, 0, 1, 3, 0, 1, 2);

dvec3 position(int v) {
    uint b = 3u * uint(v);
    return dvec3(positions[b], positions[b + 1u], positions[b + 2u]);
}
dvec3 coefficient3(int t, uint k) {
    uint b = 8u * uint(t) + k;
    return dvec3(coefficients[b], coefficients[b + 1u], coefficients[b + 2u]);
}
void add(int slot, dvec3 w) {
    uint b = 3u * uint(slot);
    scratch[b] += w.x;
    scratch[b + 1u] += w.y;
    scratch[b + 2u] += w.z;
}

void main() {
    double scale = mm_per_unit;
    for (uint id = gl_GlobalInvocationID.x; id < n; id += gl_NumWorkGroups.x * 64u) {
        int i = use_list != 0u ? row_list[id] : int(id);
        int begin = topo[o_row_offsets + uint(i)], end = topo[o_row_offsets + uint(i) + 1u];
        int d = topo[o_diagonal + uint(i)];
        for (int k = 3 * begin; k < 3 * end; ++k) scratch[k] = 0.0;
        int tet_begin = topo[o_vt_offsets + uint(i)], tet_end = topo[o_vt_offsets + uint(i) + 1u];
        dvec3 diag = dvec3(0.0);
        if (tet_begin == tet_end) diag = dvec3(1.0);  // unreferenced vertex: phi_i = 0
        double mass_diag = fem != 0u ? 0.4 : 1.0;
        for (int k = tet_begin; k < tet_end; ++k) {
            int t = topo[o_vt + uint(k)];
            uint tb = o_tets + 4u * uint(t);
            // Eq. 10, gradient form (diffusion_matrix.h tet_edge_stiffness): c_a = 6 V grad(b_a) from
            // the edges e_j = p_j - p_0 in mm, K_ab / kappa = c_a . c_b / (6 det).
            dvec3 o = position(topo[tb]);
            dvec3 e1 = (position(topo[tb + 1u]) - o) * scale;
            dvec3 e2 = (position(topo[tb + 2u]) - o) * scale;
            dvec3 e3 = (position(topo[tb + 3u]) - o) * scale;
            dvec3 c[4];
            c[1] = cross(e2, e3);
            c[2] = cross(e3, e1);
            c[3] = cross(e1, e2);
            c[0] = -(c[1] + c[2] + c[3]);
            double det = dot(e1, c[1]);
            if (!(det > 0.0)) atomicMin(bad_tet, t);
            double inv = 1.0 / (6.0 * det);
            double volume = det / 6.0;
            dvec3 kappa = coefficient3(t, 0u), mua = coefficient3(t, 3u);
            uint ib = o_inc + 4u * uint(k);
            int a = topo[ib];
            for (int s = 0; s < 3; ++s) {
                double g = 4.0 * (dot(c[a], c[kOthers[3 * a + s]]) * inv);
                dvec3 w = kappa * g;  // M_ij = 4 w_ij (Eq. 14)
                int slot = topo[ib + 1u + uint(s)];
                add(slot, fem != 0u ? w + 0.2 * mua * volume : w);
                diag -= w;  // M_ii = -4 sum_j w_ij + ... (Eq. 13)
            }
            diag += mass_diag * mua * volume;  // Eq. 13 lumped absorption (FEM: consistent mass)
        }
        // Robin boundary (Eq. 11): 4 (1 / (2A)) times the lumped or consistent face mass.
        for (int k = topo[o_vf_offsets + uint(i)]; k < topo[o_vf_offsets + uint(i) + 1u]; ++k) {
            uint fb = o_faces + 4u * uint(topo[o_vf + uint(k)]);
            dvec3 p0 = position(topo[fb]);
            double area = 0.5 * scale * scale * length(cross(position(topo[fb + 1u]) - p0, position(topo[fb + 2u]) - p0));
            double inv_a = double(coefficients[8u * uint(topo[fb + 3u]) + 6u]);
            if (fem != 0u) {
                diag += dvec3(area * inv_a / 3.0);
                add(topo[o_vf_slots + 2u * uint(k)], dvec3(area * inv_a / 6.0));
                add(topo[o_vf_slots + 2u * uint(k) + 1u], dvec3(area * inv_a / 6.0));
            } else {
                diag += dvec3(2.0 * area * inv_a / 3.0);  // Eq. 13: 2 S_i / (3A)
            }
        }
        add(d, diag);
        for (int k = begin; k < end; ++k) {
            uint s = 3u * uint(topo[o_stored + uint(k)]);
            values[s] = float(scratch[3 * k]);
            values[s + 1u] = float(scratch[3 * k + 1]);
            values[s + 2u] = float(scratch[3 * k + 2]);
        }
    }
}
)";

constexpr GLuint kGroupSize = 64;
constexpr GLuint kMaxGroups = 65535;

// OpenGL buffers of zero size cannot be bound as storage: pad empty sections' buffers.
template <typename T>
GpuBuffer upload(const GlApi& gl, std::span<const T> data) {
    if (data.empty()) return GpuBuffer(gl, sizeof(T) * 4);
    return GpuBuffer::from<T>(gl, data);
}

struct Params {
    double mm_per_unit;
    int32_t bad_tet;
    int32_t padding;
};

}  // namespace

GpuMatrixAssembly::GpuMatrixAssembly(const GlApi& gl, const TetMesh& mesh, const TetConnectivity& connectivity,
                                     const DiffusionMatrix& pattern, const GpuMatrixLayout& layout)
    : gl_(&gl), rows_(pattern.size()), tets_(mesh.tet_count()) {
    if (pattern.options.stiffness_form != StiffnessForm::Gradient)
        throw InvalidArgumentError("GPU assembly: only the gradient stiffness form is implemented on the device");
    if (rows_ != mesh.vertex_count() || layout.rows != rows_ || layout.stored_index.size() != pattern.nonzeros() ||
        pattern.tet_incidences.size() != connectivity.vertex_tets.indices.size() ||
        pattern.vertex_face_offsets.size() != rows_ + 1)
        throw InvalidArgumentError("GPU assembly: the pattern, layout, mesh and connectivity do not belong together");
    require_compute_support(gl);
    fem_ = pattern.options.discretization == Discretization::Fem;
    mm_per_unit_ = pattern.options.mm_per_unit;

    std::vector<int32_t> topo;
    std::vector<GLuint> sections;
    auto append = [&](auto&& range) {
        sections.push_back(static_cast<GLuint>(topo.size()));
        for (const auto& v : range) topo.push_back(static_cast<int32_t>(v));
    };
    std::vector<int32_t> flat;
    flat.reserve(4 * tets_);
    for (const Tet& t : mesh.tets) flat.insert(flat.end(), t.begin(), t.end());
    append(flat);
    append(pattern.offsets);
    append(pattern.diagonal);
    append(layout.stored_index);
    append(connectivity.vertex_tets.offsets);
    append(connectivity.vertex_tets.indices);
    flat.clear();
    for (const auto& inc : pattern.tet_incidences) flat.insert(flat.end(), {inc.local, inc.slots[0], inc.slots[1], inc.slots[2]});
    append(flat);
    append(pattern.vertex_face_offsets);
    append(pattern.vertex_faces);
    flat.clear();
    for (const auto& s : pattern.vertex_face_slots) flat.insert(flat.end(), {s[0], s[1]});
    append(flat);
    flat.clear();
    for (const auto& f : connectivity.boundary_faces) flat.insert(flat.end(), {f.vertices[0], f.vertices[1], f.vertices[2], f.tet});
    append(flat);
    if (topo.size() > static_cast<size_t>(INT_MAX))
        throw InvalidArgumentError("GPU assembly: the mesh is too large for 32-bit device indices");

    program_ = ComputeProgram(gl, "assemble_rows", kAssembleRows);
    program_.use();
    const char* names[] = {"o_tets", "o_row_offsets", "o_diagonal", "o_stored", "o_vt_offsets", "o_vt",
                           "o_inc", "o_vf_offsets", "o_vf", "o_vf_slots", "o_faces"};
    for (size_t k = 0; k < sections.size(); ++k) gl.Uniform1ui(program_.uniform(names[k]), sections[k]);
    gl.Uniform1ui(program_.uniform("fem"), fem_ ? 1u : 0u);

    topology_ = upload<int32_t>(gl, topo);
    coefficients_ = GpuBuffer(gl, std::max<size_t>(tets_, 1) * 8 * sizeof(float));
    scratch_ = GpuBuffer(gl, std::max<size_t>(pattern.nonzeros(), 1) * 3 * sizeof(double));
    const Params params{mm_per_unit_, INT_MAX, 0};
    params_ = GpuBuffer(gl, sizeof params, &params);
    set_positions(mesh);
    check_gpu_error(gl, "uploading the assembly's topology");
}

GpuMatrixAssembly::~GpuMatrixAssembly() = default;

void GpuMatrixAssembly::set_positions(const TetMesh& mesh) {
    if (mesh.vertex_count() != rows_ || mesh.tet_count() != tets_)
        throw InvalidArgumentError("GPU assembly: set_positions needs a mesh of the same topology");
    std::vector<double> xyz(3 * rows_);
    for (size_t v = 0; v < rows_; ++v)
        for (int k = 0; k < 3; ++k) xyz[3 * v + k] = mesh.positions[v][k];
    if (positions_.bytes() == std::max<size_t>(xyz.size(), 4) * sizeof(double) && !xyz.empty())
        positions_.write(0, xyz.size() * sizeof(double), xyz.data());
    else
        positions_ = upload<double>(*gl_, xyz);
}

void GpuMatrixAssembly::upload_coefficients(const std::vector<TetMaterial>& materials, std::span<const int32_t> which) {
    if (materials.size() != tets_)
        throw InvalidArgumentError("GPU assembly: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(tets_) + " tets");
    for (int32_t t : which)
        if (t < 0 || static_cast<size_t>(t) >= tets_)
            throw InvalidArgumentError("GPU assembly: tet index " + std::to_string(t) + " out of range");
    validate_tet_materials(materials, which);
    auto pack = [&](size_t t, float* out) {
        const DiffusionMatrix::TetCoefficients c = tet_diffusion_coefficients(materials[t]);
        for (int k = 0; k < 3; ++k) {
            out[k] = static_cast<float>(c.kappa[k]);
            out[3 + k] = static_cast<float>(c.mua[k]);
        }
        out[6] = static_cast<float>(c.inv_a);
        out[7] = static_cast<float>(c.inv_a_one_minus_fdr);
    };
    if (which.empty()) {
        std::vector<float> all(8 * tets_);
        for (size_t t = 0; t < tets_; ++t) pack(t, all.data() + 8 * t);
        if (!all.empty()) coefficients_.write(0, all.size() * sizeof(float), all.data());
        return;
    }
    // Changed tets in runs of consecutive ids, one write each (painted regions are compact in the
    // spatially ordered tet numbering, so the runs are long).
    std::vector<int32_t> sorted(which.begin(), which.end());
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    std::vector<float> run;
    for (size_t k = 0; k < sorted.size();) {
        size_t end = k + 1;
        while (end < sorted.size() && sorted[end] == sorted[end - 1] + 1) ++end;
        run.resize(8 * (end - k));
        for (size_t j = k; j < end; ++j) pack(static_cast<size_t>(sorted[j]), run.data() + 8 * (j - k));
        coefficients_.write(static_cast<size_t>(sorted[k]) * 8 * sizeof(float), run.size() * sizeof(float), run.data());
        k = end;
    }
}

void GpuMatrixAssembly::run(GpuMatrix& target, size_t count, const GpuBuffer* row_list) {
    if (target.layout.rows != rows_) throw InvalidArgumentError("GPU assembly: the target matrix has another size");
    if (count == 0) return;
    const int32_t no_bad_tet = INT_MAX;
    params_.write(offsetof(Params, bad_tet), sizeof no_bad_tet, &no_bad_tet);
    const GpuBuffer empty_list = row_list ? GpuBuffer() : GpuBuffer(*gl_, 4 * sizeof(int32_t));
    program_.use();
    topology_.bind(0);
    positions_.bind(1);
    coefficients_.bind(2);
    scratch_.bind(3);
    params_.bind(4);
    (row_list ? *row_list : empty_list).bind(5);
    target.values.bind(6);
    gl_->Uniform1ui(program_.uniform("n"), static_cast<GLuint>(count));
    gl_->Uniform1ui(program_.uniform("use_list"), row_list ? 1u : 0u);
    program_.dispatch(static_cast<GLuint>(std::clamp<size_t>((count + kGroupSize - 1) / kGroupSize, 1, kMaxGroups)));
    check_gpu_error(*gl_, "assembling the matrix");
    Params params{};
    params_.read(0, sizeof params, &params);
    if (params.bad_tet != INT_MAX)
        throw InvalidMeshError("GPU assembly: tet " + std::to_string(params.bad_tet) +
                               " has non-positive volume (inverted or degenerate)");
}

void GpuMatrixAssembly::assemble(const std::vector<TetMaterial>& materials, GpuMatrix& target) {
    upload_coefficients(materials, {});
    run(target, rows_, nullptr);
}

std::vector<int32_t> GpuMatrixAssembly::update(const TetMesh& mesh, const std::vector<TetMaterial>& materials,
                                               std::span<const int32_t> changed_tets, GpuMatrix& target) {
    if (mesh.tet_count() != tets_ || mesh.vertex_count() != rows_)
        throw InvalidArgumentError("GPU assembly: update needs the mesh the assembly was built for");
    if (changed_tets.empty()) return {};
    upload_coefficients(materials, changed_tets);
    // A tet's material enters exactly the rows of its four vertices (update_diffusion_matrix).
    std::vector<int32_t> rows;
    rows.reserve(4 * changed_tets.size());
    for (int32_t t : changed_tets) rows.insert(rows.end(), mesh.tets[t].begin(), mesh.tets[t].end());
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    const GpuBuffer list = GpuBuffer::from<int32_t>(*gl_, rows);
    run(target, rows.size(), &list);
    return rows;
}

}  // namespace waxwork
