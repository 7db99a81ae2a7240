#include "solver/diffusion_matrix.h"

#include "base/error.h"
#include "solver/material.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>

namespace waxwork {
namespace {

// For local vertex a, the other three in ascending order (the order of TetIncidence::slots).
constexpr std::array<std::array<int, 3>, 4> kOthers = {{{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};

constexpr size_t kRowGrain = 512;
// Materials are compared bitwise (assemble_diffusion_values): valid only without padding bytes.
static_assert(sizeof(TetMaterial) == 7 * sizeof(double), "TetMaterial must have no padding");

}  // namespace

DiffusionMatrix::TetCoefficients tet_diffusion_coefficients(const TetMaterial& m) {
    DiffusionMatrix::TetCoefficients c{};
    for (int ch = 0; ch < 3; ++ch) {
        c.kappa[ch] = diffusion_coefficient(m.mua[ch], m.musp[ch]);
        c.mua[ch] = m.mua[ch];
    }
    const double fdr = diffuse_fresnel_reflectance(m.eta);
    const double a = (1.0 + fdr) / (1.0 - fdr);
    c.inv_a = 1.0 / a;
    c.inv_a_one_minus_fdr = 1.0 / (a * (1.0 - fdr));
    return c;
}

namespace {

void check_materials(const TetMesh& mesh, const std::vector<TetMaterial>& materials) {
    if (materials.size() != mesh.tet_count())
        throw InvalidArgumentError("diffusion matrix: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(mesh.tet_count()) + " tets");
}

// A boundary face's source weight before the face mass splits it among the corners (Eq. 12):
// 4 (1 / (2A)) from the Robin term times the 4 / (1 - F_dr) of Eq. 2, per unit of area. The lumped
// mass gives each corner a third of it, the consistent one S/6 on the diagonal and S/12 off it.
double face_source_weight(const DiffusionMatrix::TetCoefficients& co, double area) {
    return 8.0 * co.inv_a_one_minus_fdr * area;
}

}  // namespace

void validate_tet_materials(const std::vector<TetMaterial>& materials, std::span<const int32_t> which) {
    std::atomic<int64_t> first_bad{-1};
    auto check = [&](int64_t t) {
        try {
            validate_material(materials[t]);
        } catch (const InvalidArgumentError&) {
            int64_t seen = first_bad.load();
            while ((seen < 0 || t < seen) && !first_bad.compare_exchange_weak(seen, t)) {
            }
        }
    };
    const size_t n = which.empty() ? materials.size() : which.size();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) check(which.empty() ? static_cast<int64_t>(k) : which[k]);
    });
    if (first_bad >= 0) validate_material(materials[first_bad], "material of tet " + std::to_string(first_bad.load()));
}

namespace {

// Writes row i of all three matrices and of the source operator from the cached geometry and
// coefficients. Only row i is written, so rows can be assembled in parallel without races.
// Templated on the discretisation so that the per-incidence loop carries no FEM branches, and written
// on raw row pointers: this loop is most of a material change's cost (bench/solver_bench.cpp,
// BM_AssembleValues), and its summation order is the one every caller (full assembly and
// update_diffusion_matrix) shares, so both still agree bit for bit.
template <bool Fem>
void assemble_row_impl(DiffusionMatrix& m, const TetConnectivity& conn, int32_t i) {
    const int32_t begin = m.offsets[i], end = m.offsets[i + 1];
    std::array<double*, 3> val = {m.values[0].data(), m.values[1].data(), m.values[2].data()};
    double* const source = m.source.data();
    for (double* v : val) std::fill(v + begin, v + end, 0.0);
    std::fill(source + begin, source + end, 0.0);
    const int32_t d = m.diagonal[i];
    const int32_t tet_begin = conn.vertex_tets.offsets[i], tet_end = conn.vertex_tets.offsets[i + 1];
    if (tet_begin == tet_end) {  // unreferenced vertex: phi_i = 0
        for (double* v : val) v[d] = 1.0;
        return;
    }
    // Lumped absorption (Eq. 13: V_i mu = sum_t 4 * mu V_t / 4); consistent: 4 mu V (1 + delta) / 20.
    constexpr double mass_diag = Fem ? 0.4 : 1.0;
    constexpr double mass_off = 0.2;
    const int32_t* tets = conn.vertex_tets.indices.data();
    const DiffusionMatrix::TetIncidence* incidences = m.tet_incidences.data();
    const DiffusionMatrix::TetGeometry* geometry = m.tet_geometry.data();
    const DiffusionMatrix::TetCoefficients* coefficients = m.tet_coefficients.data();
    double diag0 = 0, diag1 = 0, diag2 = 0;
    for (int32_t k = tet_begin; k < tet_end; ++k) {
        const int32_t t = tets[k];
        const auto& inc = incidences[k];
        const auto& geo = geometry[t];
        const auto& co = coefficients[t];
        const double k0 = co.kappa[0], k1 = co.kappa[1], k2 = co.kappa[2];
        for (int s = 0; s < 3; ++s) {
            const double g = 4.0 * geo.edge_stiffness[tet_edge_index(inc.local, kOthers[inc.local][s])];
            const int32_t slot = inc.slots[s];
            const double w0 = k0 * g, w1 = k1 * g, w2 = k2 * g;  // M_ij = 4 w_ij (Eq. 14)
            val[0][slot] += w0;
            val[1][slot] += w1;
            val[2][slot] += w2;
            // M_ii = -4 sum_j w_ij + ... (Eq. 13): the stiffness annihilates constants.
            diag0 -= w0;
            diag1 -= w1;
            diag2 -= w2;
            if constexpr (Fem) {
                for (int c = 0; c < 3; ++c) val[c][slot] += mass_off * co.mua[c] * geo.volume;
            }
        }
        diag0 += mass_diag * co.mua[0] * geo.volume;
        diag1 += mass_diag * co.mua[1] * geo.volume;
        diag2 += mass_diag * co.mua[2] * geo.volume;
    }
    std::array<double, 3> diag = {diag0, diag1, diag2};
    // Robin boundary (Eq. 11 times -4|Upsilon|): 4 (1 / (2A)) times the lumped (S_f / 3) or consistent
    // (S_f (1 + delta) / 12) face mass; the source carries the extra 4 / (1 - F_dr) of Eq. 2 (Eq. 12).
    double source_diag = 0;
    for (int32_t k = m.vertex_face_offsets[i]; k < m.vertex_face_offsets[i + 1]; ++k) {
        const int32_t f = m.vertex_faces[k];
        const double area = m.boundary_face_area[f];
        const auto& co = m.tet_coefficients[conn.boundary_faces[f].tet];
        if constexpr (Fem) {
            const double r_diag = area * co.inv_a / 3.0, r_off = area * co.inv_a / 6.0;
            const double s_diag = face_source_weight(co, area) / 6.0;
            const double s_off = face_source_weight(co, area) / 12.0;
            for (int c = 0; c < 3; ++c) diag[c] += r_diag;
            source_diag += s_diag;
            for (int32_t slot : m.vertex_face_slots[k]) {
                for (int c = 0; c < 3; ++c) val[c][slot] += r_off;
                source[slot] += s_off;
            }
        } else {
            for (int c = 0; c < 3; ++c) diag[c] += 2.0 * area * co.inv_a / 3.0;  // Eq. 13: 2 S_i / (3A)
            source_diag += face_source_weight(co, area) / 3.0;                    // Eq. 12
        }
    }
    for (int c = 0; c < 3; ++c) val[c][d] += diag[c];
    source[d] += source_diag;
}

// A tet's K_ab / kappa and volume in millimetres.
DiffusionMatrix::TetGeometry tet_geometry_mm(const TetMesh& mesh, const Tet& tet, const AssemblyOptions& options) {
    // Relative to the first vertex before scaling: keeps the rounding of large coordinates out.
    const double scale = options.mm_per_unit;
    const Eigen::Vector3d o = mesh.positions[tet[0]];
    const Eigen::Vector3d p1 = (mesh.positions[tet[1]] - o) * scale;
    const Eigen::Vector3d p2 = (mesh.positions[tet[2]] - o) * scale;
    const Eigen::Vector3d p3 = (mesh.positions[tet[3]] - o) * scale;
    return {tet_edge_stiffness<double>(Eigen::Vector3d::Zero(), p1, p2, p3, options.stiffness_form),
            p1.dot(p2.cross(p3)) / 6.0};
}

double boundary_face_area_mm(const TetMesh& mesh, const std::array<int32_t, 3>& v, double scale) {
    return 0.5 * scale * scale *
           (mesh.positions[v[1]] - mesh.positions[v[0]]).cross(mesh.positions[v[2]] - mesh.positions[v[0]]).norm();
}

[[noreturn]] void throw_inverted_tet(int64_t tet) {
    throw InvalidMeshError("diffusion matrix: tet " + std::to_string(tet) + " has non-positive volume (inverted or degenerate)");
}

void assemble_row(DiffusionMatrix& m, const TetConnectivity& conn, int32_t i) {
    if (m.options.discretization == Discretization::Fem)
        assemble_row_impl<true>(m, conn, i);
    else
        assemble_row_impl<false>(m, conn, i);
}

}  // namespace

template <typename Scalar>
std::array<Scalar, 6> tet_edge_stiffness(const Eigen::Matrix<Scalar, 3, 1>& p0, const Eigen::Matrix<Scalar, 3, 1>& p1,
                                         const Eigen::Matrix<Scalar, 3, 1>& p2, const Eigen::Matrix<Scalar, 3, 1>& p3,
                                         StiffnessForm form) {
    using Vec = Eigen::Matrix<Scalar, 3, 1>;
    std::array<Scalar, 6> k{};
    if (form == StiffnessForm::Gradient) {
        // 6 V grad(b_a) = c_a: c_1 = e2 x e3, c_2 = e3 x e1, c_3 = e1 x e2, c_0 = -(c_1 + c_2 + c_3),
        // with e_j = p_j - p0. K_ab / kappa = V grad(b_a).grad(b_b) = c_a . c_b / (36 V) = c_a . c_b / (6 det).
        const Vec e1 = p1 - p0, e2 = p2 - p0, e3 = p3 - p0;
        std::array<Vec, 4> c;
        c[1] = e2.cross(e3);
        c[2] = e3.cross(e1);
        c[3] = e1.cross(e2);
        c[0] = -(c[1] + c[2] + c[3]);
        const Scalar det = e1.dot(c[1]);
        const Scalar inv = Scalar(1) / (Scalar(6) * det);
        for (int e = 0; e < 6; ++e) k[e] = c[kTetEdges[e][0]].dot(c[kTetEdges[e][1]]) * inv;
    } else {
        // Eq. 10: for edge (a, b) the opposite edge is (k, l); theta_kl is the dihedral angle there,
        // between faces (k, l, a) and (k, l, b), whose normals n1 = (l - k) x (a - k), n2 = (l - k) x (b - k)
        // enclose exactly theta_kl.
        const std::array<const Vec*, 4> p = {&p0, &p1, &p2, &p3};
        for (int e = 0; e < 6; ++e) {
            const int a = kTetEdges[e][0], b = kTetEdges[e][1];
            const int kl = 5 - e;  // kTetEdges lists opposite edges symmetrically: (0,1)<->(2,3), ...
            const int kk = kTetEdges[kl][0], ll = kTetEdges[kl][1];
            const Vec edge = *p[ll] - *p[kk];
            const Vec n1 = edge.cross(*p[a] - *p[kk]).normalized();
            const Vec n2 = edge.cross(*p[b] - *p[kk]).normalized();
            const Scalar cot = n1.dot(n2) / n1.cross(n2).norm();
            k[e] = -edge.norm() * cot / Scalar(6);
        }
    }
    return k;
}

template std::array<float, 6> tet_edge_stiffness<float>(const Eigen::Vector3f&, const Eigen::Vector3f&,
                                                        const Eigen::Vector3f&, const Eigen::Vector3f&, StiffnessForm);
template std::array<double, 6> tet_edge_stiffness<double>(const Eigen::Vector3d&, const Eigen::Vector3d&,
                                                          const Eigen::Vector3d&, const Eigen::Vector3d&, StiffnessForm);
template std::array<long double, 6> tet_edge_stiffness<long double>(
    const Eigen::Matrix<long double, 3, 1>&, const Eigen::Matrix<long double, 3, 1>&,
    const Eigen::Matrix<long double, 3, 1>&, const Eigen::Matrix<long double, 3, 1>&, StiffnessForm);

DiffusionMatrix assemble_diffusion_pattern(const TetMesh& mesh, const TetConnectivity& conn,
                                           const AssemblyOptions& options) {
    validate_mm_per_unit(options.mm_per_unit, "diffusion matrix: mm_per_unit");
    if (conn.vertex_tets.row_count() != mesh.vertex_count() || conn.vertex_vertices.row_count() != mesh.vertex_count())
        throw InvalidArgumentError("diffusion matrix: connectivity does not match the mesh (rebuild it after edits)");

    const size_t n = mesh.vertex_count();
    DiffusionMatrix m;
    m.options = options;

    // Boundary faces per vertex, ascending (a parallel counting sort, connectivity.h).
    const auto& faces = conn.boundary_faces;
    std::vector<std::array<int32_t, 3>> face_vertices(faces.size());
    for (size_t f = 0; f < faces.size(); ++f) face_vertices[f] = faces[f].vertices;
    CompressedRows vertex_faces = vertex_elements(face_vertices, n);
    m.vertex_face_offsets = std::move(vertex_faces.offsets);
    m.vertex_faces = std::move(vertex_faces.indices);
    m.vertex_face_slots.resize(m.vertex_faces.size());

    // Pattern: the one-ring plus the diagonal, columns ascending.
    m.offsets.resize(n + 1);
    m.offsets[0] = 0;
    for (size_t i = 0; i < n; ++i)
        m.offsets[i + 1] = m.offsets[i] + static_cast<int32_t>(conn.vertex_vertices.row(i).size()) + 1;
    m.columns.resize(static_cast<size_t>(m.offsets.back()));
    m.diagonal.resize(n);
    m.tet_incidences.resize(conn.vertex_tets.indices.size());
    // Row by row: the columns, then the slots of the row's tet and face incidences, looked up in a
    // per-thread table of where each column of the row sits (written once per entry of the row) rather
    // than by a binary search per slot. Only the row's own columns are read back, so the table is never
    // cleared.
    tbb::enumerable_thread_specific<std::vector<int32_t>> slot_tables([n] { return std::vector<int32_t>(n); });
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kRowGrain), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<int32_t>& slot_of = slot_tables.local();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const auto self = static_cast<int32_t>(i);
            const auto ring = conn.vertex_vertices.row(i);
            const auto split = std::lower_bound(ring.begin(), ring.end(), self);
            int32_t* out = m.columns.data() + m.offsets[i];
            out = std::copy(ring.begin(), split, out);
            m.diagonal[i] = static_cast<int32_t>(out - m.columns.data());
            *out++ = self;
            std::copy(split, ring.end(), out);
            for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k) slot_of[static_cast<size_t>(m.columns[k])] = k;

            for (int32_t k = conn.vertex_tets.offsets[i]; k < conn.vertex_tets.offsets[i + 1]; ++k) {
                const Tet& tet = mesh.tets[static_cast<size_t>(conn.vertex_tets.indices[k])];
                auto& inc = m.tet_incidences[static_cast<size_t>(k)];
                inc.local = static_cast<int32_t>(std::find(tet.begin(), tet.end(), self) - tet.begin());
                for (int s = 0; s < 3; ++s) inc.slots[s] = slot_of[static_cast<size_t>(tet[kOthers[inc.local][s]])];
            }
            for (int32_t k = m.vertex_face_offsets[i]; k < m.vertex_face_offsets[i + 1]; ++k) {
                const auto& v = faces[static_cast<size_t>(m.vertex_faces[k])].vertices;
                const int a = v[0] == self ? 0 : v[1] == self ? 1 : 2;
                m.vertex_face_slots[static_cast<size_t>(k)] = {slot_of[static_cast<size_t>(v[(a + 1) % 3])],
                                                               slot_of[static_cast<size_t>(v[(a + 2) % 3])]};
            }
        }
    });
    return m;
}

DiffusionMatrix assemble_diffusion_matrix(const TetMesh& mesh, const TetConnectivity& conn,
                                          const std::vector<TetMaterial>& materials, const AssemblyOptions& options) {
    check_materials(mesh, materials);
    DiffusionMatrix m = assemble_diffusion_pattern(mesh, conn, options);

    // Per tet: geometry in mm.
    const size_t tet_count = mesh.tet_count();
    m.tet_geometry.resize(tet_count);
    std::atomic<int64_t> bad_tet{-1};
    const double scale = options.mm_per_unit;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tet_count, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
            m.tet_geometry[t] = tet_geometry_mm(mesh, mesh.tets[t], options);
            if (!(m.tet_geometry[t].volume > 0)) bad_tet = static_cast<int64_t>(t);
        }
    });
    if (bad_tet >= 0) throw_inverted_tet(bad_tet);
    const auto& faces = conn.boundary_faces;
    m.boundary_face_area.resize(faces.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, faces.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t f = r.begin(); f != r.end(); ++f)
            m.boundary_face_area[f] = boundary_face_area_mm(mesh, faces[f].vertices, scale);
    });

    assemble_diffusion_values(m, conn, materials);
    return m;
}

void assemble_diffusion_values(DiffusionMatrix& m, const TetConnectivity& conn, const std::vector<TetMaterial>& materials) {
    const size_t tet_count = m.tet_geometry.size();
    if (materials.size() != tet_count)
        throw InvalidArgumentError("diffusion matrix: " + std::to_string(materials.size()) + " materials for " +
                                   std::to_string(tet_count) + " tets");
    validate_tet_materials(materials, {});
    m.tet_coefficients.resize(tet_count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tet_count, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
            // Materials come in long runs (painted regions, whole-object presets): a bitwise repeat of
            // the previous tet's material reuses its coefficients (identical bits, no divisions).
            if (t > r.begin() && std::memcmp(&materials[t], &materials[t - 1], sizeof(TetMaterial)) == 0)
                m.tet_coefficients[t] = m.tet_coefficients[t - 1];
            else
                m.tet_coefficients[t] = tet_diffusion_coefficients(materials[t]);
        }
    });
    for (auto& v : m.values) v.resize(m.columns.size());
    m.source.resize(m.columns.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m.size(), kRowGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) assemble_row(m, conn, static_cast<int32_t>(i));
    });
}

std::vector<int32_t> update_diffusion_matrix(DiffusionMatrix& m, const TetMesh& mesh, const TetConnectivity& conn,
                                             const std::vector<TetMaterial>& materials,
                                             std::span<const int32_t> changed_tets) {
    if (materials.size() != m.tet_coefficients.size() || mesh.tet_count() != m.tet_coefficients.size())
        throw InvalidArgumentError("diffusion matrix update: " + std::to_string(materials.size()) + " materials and " +
                                   std::to_string(mesh.tet_count()) + " tets for a matrix assembled on " +
                                   std::to_string(m.tet_coefficients.size()) + " tets");
    for (int32_t t : changed_tets)
        if (t < 0 || static_cast<size_t>(t) >= materials.size())
            throw InvalidArgumentError("diffusion matrix update: tet index " + std::to_string(t) + " out of range");
    if (changed_tets.empty()) return {};
    validate_tet_materials(materials, changed_tets);
    // A tet's material enters exactly the rows of its four vertices (its edges, its mass and, through
    // eta, its boundary faces all lie in those rows), so rewriting them reproduces a full assembly.
    std::vector<int32_t> rows;
    rows.reserve(4 * changed_tets.size());
    for (int32_t t : changed_tets) {
        m.tet_coefficients[t] = tet_diffusion_coefficients(materials[t]);
        rows.insert(rows.end(), mesh.tets[t].begin(), mesh.tets[t].end());
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) assemble_row(m, conn, rows[k]);
    });
    return rows;
}

std::vector<int32_t> update_diffusion_geometry(DiffusionMatrix& m, const TetMesh& mesh, const TetConnectivity& conn,
                                               std::span<const int32_t> moved_vertices) {
    const size_t n = m.size();
    if (mesh.vertex_count() != n || mesh.tet_count() != m.tet_geometry.size() ||
        conn.vertex_tets.row_count() != n || conn.boundary_faces.size() != m.boundary_face_area.size())
        throw InvalidArgumentError("diffusion matrix geometry update: the mesh (" + std::to_string(mesh.vertex_count()) +
                                   " vertices, " + std::to_string(mesh.tet_count()) + " tets) is not the one the matrix (" +
                                   std::to_string(n) + " vertices, " + std::to_string(m.tet_geometry.size()) +
                                   " tets) was assembled on");
    for (const int32_t v : moved_vertices)
        if (v < 0 || static_cast<size_t>(v) >= n)
            throw InvalidArgumentError("diffusion matrix geometry update: vertex index " + std::to_string(v) + " out of range");
    // Marks rather than sorted lists: a drag moves most of a body, and sorting its tets' incidences
    // costs more than the rows' assembly.
    std::vector<uint8_t> tet_moved(m.tet_geometry.size(), 0), face_moved(m.boundary_face_area.size(), 0);
    for (const int32_t v : moved_vertices) {
        for (const int32_t t : conn.vertex_tets.row(v)) tet_moved[t] = 1;
        for (int32_t k = m.vertex_face_offsets[v]; k < m.vertex_face_offsets[v + 1]; ++k) face_moved[m.vertex_faces[k]] = 1;
    }
    const auto marked = [](const std::vector<uint8_t>& flags) {
        std::vector<int32_t> list;
        for (size_t i = 0; i < flags.size(); ++i)
            if (flags[i]) list.push_back(static_cast<int32_t>(i));
        return list;
    };
    const std::vector<int32_t> tets = marked(tet_moved), faces = marked(face_moved);
    // New geometry first, so an inverted tet throws before the matrix changes.
    std::vector<DiffusionMatrix::TetGeometry> geometry(tets.size());
    std::atomic<int64_t> bad_tet{-1};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tets.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) {
            geometry[k] = tet_geometry_mm(mesh, mesh.tets[tets[k]], m.options);
            if (!(geometry[k].volume > 0)) bad_tet = tets[k];
        }
    });
    if (bad_tet >= 0) throw_inverted_tet(bad_tet);
    // The moved geometry enters exactly the rows of those tets' vertices (a boundary face lies in its
    // tet, so its vertices are among them).
    std::vector<uint8_t> row_changed(n, 0);
    for (size_t k = 0; k < tets.size(); ++k) {
        m.tet_geometry[tets[k]] = geometry[k];
        for (const int32_t v : mesh.tets[tets[k]]) row_changed[v] = 1;
    }
    for (const int32_t f : faces)
        m.boundary_face_area[f] = boundary_face_area_mm(mesh, conn.boundary_faces[f].vertices, m.options.mm_per_unit);
    const std::vector<int32_t> rows = marked(row_changed);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t k = r.begin(); k != r.end(); ++k) assemble_row(m, conn, rows[k]);
    });
    return rows;
}

void diffusion_right_hand_side(const DiffusionMatrix& m, const std::vector<std::array<double, 3>>& q, int channel,
                               std::span<double> b) {
    if (q.size() != m.size() || b.size() != m.size())
        throw InvalidArgumentError("diffusion right-hand side: sizes of q (" + std::to_string(q.size()) + ") and b (" +
                                   std::to_string(b.size()) + ") must equal the vertex count " +
                                   std::to_string(m.size()));
    if (channel < 0 || channel > 2) throw InvalidArgumentError("diffusion right-hand side: channel must be 0, 1 or 2");
    tbb::parallel_for(tbb::blocked_range<size_t>(0, m.size(), kRowGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            double sum = 0;
            if (m.vertex_face_offsets[i] != m.vertex_face_offsets[i + 1])
                for (int32_t k = m.offsets[i]; k < m.offsets[i + 1]; ++k) sum += m.source[k] * q[m.columns[k]][channel];
            b[i] = sum;
        }
    });
}

void add_corner_light(const DiffusionMatrix& m, std::span<const CornerLight> corners, int channel,
                      std::span<double> b, std::span<const uint8_t> rows) {
    if (channel < 0 || channel > 2) throw InvalidArgumentError("corner light: channel must be 0, 1 or 2");
    if (b.size() != m.size() || (!rows.empty() && rows.size() != m.size()))
        throw InvalidArgumentError("corner light: b (" + std::to_string(b.size()) + ") and the row mask (" +
                                   std::to_string(rows.size()) + ") must have the vertex count " +
                                   std::to_string(m.size()));
    const bool fem = m.options.discretization == Discretization::Fem;
    // Serial: corners lie along creases only (a few percent of the surface at most), and neighbouring
    // corners add to the same rows.
    for (const CornerLight& corner : corners) {
        if (corner.face < 0 || static_cast<size_t>(corner.face) >= m.boundary_face_area.size() || corner.tet < 0 ||
            static_cast<size_t>(corner.tet) >= m.tet_coefficients.size() ||
            std::any_of(corner.vertices.begin(), corner.vertices.end(),
                        [&](int32_t v) { return v < 0 || static_cast<size_t>(v) >= m.size(); }))
            throw InvalidArgumentError("corner light: face " + std::to_string(corner.face) + " of tet " +
                                       std::to_string(corner.tet) + " is not in the matrix");
        // The face's source entries, as assemble_row_impl adds them, times this corner's own light.
        const double weight =
            face_source_weight(m.tet_coefficients[corner.tet], m.boundary_face_area[corner.face]) * corner.delta[channel];
        const auto add = [&](int32_t row, double value) {
            if (rows.empty() || rows[row]) b[row] += value;
        };
        if (fem) {
            add(corner.vertices[0], weight / 6.0);
            add(corner.vertices[1], weight / 12.0);
            add(corner.vertices[2], weight / 12.0);
        } else {
            add(corner.vertices[0], weight / 3.0);
        }
    }
}

std::vector<double> lumped_vertex_volumes(const DiffusionMatrix& m, const TetConnectivity& conn) {
    std::vector<double> volumes(m.size(), 0.0);
    for (size_t i = 0; i < m.size(); ++i)
        for (int32_t k = conn.vertex_tets.offsets[i]; k < conn.vertex_tets.offsets[i + 1]; ++k)
            volumes[i] += m.tet_geometry[conn.vertex_tets.indices[k]].volume / 4.0;
    return volumes;
}

}  // namespace waxwork
