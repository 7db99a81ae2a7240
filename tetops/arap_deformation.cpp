#include "tetops/arap_deformation.h"

#include "base/error.h"
#include "base/parallel_rows.h"
#include "base/progress.h"
#include "base/timing.h"
#include "tetops/quality.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#ifdef WAXWORK_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace waxwork {

namespace {

constexpr size_t kTetGrain = 1024;
constexpr size_t kVertexGrain = 1024;

// The rotation nearest F (its polar part): U V^T of the SVD F = U S V^T, with the column of U of the
// smallest singular value negated when U V^T would be a reflection (Sorkine and Alexa 2007, remark
// after Eq. 6), so an inverted tet still gets a proper rotation to be pulled back towards.
Eigen::Matrix3d nearest_rotation_svd(const Eigen::Matrix3d& f) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d u = svd.matrixU();
    const Eigen::Matrix3d& v = svd.matrixV();
    if ((u * v.transpose()).determinant() < 0) u.col(2) = -u.col(2);
    return u * v.transpose();
}

// The same rotation for det F > 0, where it is the orthogonal polar factor of F, by Higham's scaled
// Newton iteration X <- (g X + X^{-T} / g) / 2, g = |det X|^{-1/3} (Higham 1986, "Computing the polar
// decomposition", Eq. 3.1 with determinant scaling): quadratic convergence from X = F, a few 3x3
// inverses per tet, against a Jacobi SVD that costs several times more and was most of an
// iteration's time. A tet with det F <= 0 (inverted or flat: the polar factor would be a reflection)
// or one that has not converged in kMaxSteps steps takes the SVD.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& f) {
    constexpr int kMaxSteps = 30;
    double det = f.determinant();
    if (!(det > 1e-300)) return nearest_rotation_svd(f);
    Eigen::Matrix3d x = f;
    for (int step = 0; step < kMaxSteps; ++step) {
        const double g = step < 6 ? std::cbrt(1 / det) : 1.0;  // scaling only speeds the early steps
        const Eigen::Matrix3d next = 0.5 * (g * x + x.inverse().transpose() / g);
        const double change = (next - x).lpNorm<Eigen::Infinity>();
        x = next;
        // Quadratic convergence: one more step after a change of 1e-8 leaves an error near 1e-16.
        if (change < 1e-8) return 0.5 * (x + x.inverse().transpose());
        det = x.determinant();
        if (!(det > 0)) break;
    }
    return nearest_rotation_svd(f);
}

// The float local step's batch: Newton's iteration above on kLanes tets at once, each 3x3 entry one
// vector of kLanes floats (GCC's and Clang's vector extensions: one SSE register, so every operation
// below is one instruction for all lanes; Eigen's 3x3 types are not vectorised, and GCC did not
// vectorise the same loops written over arrays). Written by hand because no Debian library
// vectorises many small polar decompositions (McAdams et al. 2011 do it for the SVD with hand-written
// intrinsics).
using Lanes = float __attribute__((vector_size(16)));
using LaneMask = int32_t __attribute__((vector_size(16)));
constexpr int kLanes = 4;

// Cofactors C of each lane's X (C_ij = (-1)^(i+j) minor_ij, so X^-T = C / det X; entry (i, j) at
// 3 i + j) and determinants.
inline void lane_cofactors(const Lanes (&x)[9], Lanes (&c)[9], Lanes& det) {
    c[0] = x[4] * x[8] - x[5] * x[7];
    c[1] = x[5] * x[6] - x[3] * x[8];
    c[2] = x[3] * x[7] - x[4] * x[6];
    c[3] = x[2] * x[7] - x[1] * x[8];
    c[4] = x[0] * x[8] - x[2] * x[6];
    c[5] = x[1] * x[6] - x[0] * x[7];
    c[6] = x[1] * x[5] - x[2] * x[4];
    c[7] = x[2] * x[3] - x[0] * x[5];
    c[8] = x[0] * x[4] - x[1] * x[3];
    det = x[0] * c[0] + x[1] * c[1] + x[2] * c[2];
}

// The polar factors of f[0..count) in float; bit l of the result is set when lane l needs the double
// path instead (det F <= 0, an iterate that lost its positive determinant, no convergence). Unscaled
// Newton (X <- (X + X^-T) / 2): ARAP's F_t are near rotations (singular values near 1), where
// scaling saves little, and it would cost a root per lane and step; a far-stretched tet only takes
// more steps (each halves a large singular value), up to kMaxSteps, then the double path.
uint32_t nearest_rotations_float(const std::array<Eigen::Matrix3d, kLanes>& f, int count,
                                 std::array<Eigen::Matrix3d, kLanes>& r) {
    // A change under 1e-4 leaves an error near 1e-8 after one more step (quadratic convergence),
    // below float's precision.
    constexpr float kTolerance = 1e-4f;
    constexpr int kMaxSteps = 24;
    const Lanes zero = {0, 0, 0, 0}, one = {1, 1, 1, 1};
    Lanes x[9], c[9], det;
    for (int k = 0; k < 9; ++k)
        for (int l = 0; l < kLanes; ++l)
            x[k][l] = l < count ? static_cast<float>(f[l](k / 3, k % 3)) : (k % 4 == 0 ? 1.f : 0.f);
    LaneMask bad = {0, 0, 0, 0};
    bool converged = false;
    for (int step = 0; step < kMaxSteps && !converged; ++step) {
        lane_cofactors(x, c, det);
        // A lane that lost its positive determinant (or became NaN) goes on harmlessly with det 1;
        // its result is dropped.
        const LaneMask positive = det > zero;
        bad |= ~positive;
        det = positive ? det : one;
        const Lanes half_inverse = 0.5f / det;
        Lanes change = zero;
        for (int k = 0; k < 9; ++k) {
            const Lanes next = 0.5f * x[k] + half_inverse * c[k];
            const Lanes diff = next - x[k];
            const Lanes size = diff < zero ? -diff : diff;
            change = size > change ? size : change;
            x[k] = next;
        }
        change = bad ? zero : change;
        float largest = 0;
        for (int l = 0; l < kLanes; ++l) largest = std::max(largest, change[l]);
        converged = largest < kTolerance;
    }
    lane_cofactors(x, c, det);
    uint32_t fallback = 0;
    for (int l = 0; l < count; ++l) {
        if (!converged || bad[l] || !(det[l] > 0)) {
            fallback |= 1u << l;
            continue;
        }
        const double half_inverse = 0.5 / double(det[l]);
        for (int k = 0; k < 9; ++k) r[l](k / 3, k % 3) = 0.5 * double(x[k][l]) + half_inverse * double(c[k][l]);
    }
    return fallback;
}

std::string point_text(const Eigen::Vector3d& p) {
    std::ostringstream out;
    out << p.x() << "," << p.y() << "," << p.z();
    return out.str();
}

}  // namespace

struct ArapDeformer::Factor {
    using Matrix = Eigen::SparseMatrix<double>;
#ifdef WAXWORK_HAVE_CHOLMOD
    std::unique_ptr<Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower>> cholmod;
#endif
    std::unique_ptr<Eigen::SimplicialLLT<Matrix, Eigen::Lower>> eigen;
    Matrix k_fc;  // free rows, constrained columns: moves to the right-hand side

    // Factors k_ff as `kind` asks; false when the factorisation failed.
    bool compute(const Matrix& k_ff, ArapFactor kind) {
#ifdef WAXWORK_HAVE_CHOLMOD
        if (kind != ArapFactor::EigenSimplicialLLT) {
            cholmod = std::make_unique<Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower>>();
            if (kind == ArapFactor::CholmodSimplicialSolves) {
                // After the supernodal factorisation, cholmod_factorize converts the factor (CHOLMOD's
                // Common->final_* options): simplicial, LL^T, packed, the amalgamation's zeros removed.
                cholmod_common& common = cholmod->cholmod();
                common.final_asis = 0;
                common.final_super = 0;
                common.final_ll = 1;
                common.final_pack = 1;
                common.final_monotonic = 1;
                common.final_resymbol = 1;
            }
            cholmod->compute(k_ff);
            return cholmod->info() == Eigen::Success;
        }
#else
        (void)kind;
#endif
        eigen = std::make_unique<Eigen::SimplicialLLT<Matrix, Eigen::Lower>>();
        eigen->compute(k_ff);
        return eigen->info() == Eigen::Success;
    }

    Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const {
#ifdef WAXWORK_HAVE_CHOLMOD
        if (cholmod) return cholmod->solve(rhs);
#endif
        return eigen->solve(rhs);
    }
};

ArapDeformer::~ArapDeformer() = default;
ArapDeformer::ArapDeformer(ArapDeformer&&) noexcept = default;
ArapDeformer& ArapDeformer::operator=(ArapDeformer&&) noexcept = default;

ArapDeformer::ArapDeformer(const TetMesh& mesh, std::vector<int32_t> body_tets, ArapOptions options)
    : options_(options), rest_(mesh.positions), positions_(mesh.positions), body_tets_(std::move(body_tets)) {
    if (body_tets_.empty()) throw InvalidArgumentError("ARAP deformation: the body has no tets");
    local_index_.assign(mesh.vertex_count(), -1);
    tets_.reserve(body_tets_.size());
    for (int32_t t : body_tets_) {
        if (t < 0 || static_cast<size_t>(t) >= mesh.tet_count())
            throw InvalidArgumentError("ARAP deformation: tet index " + std::to_string(t) + " out of range");
        tets_.push_back(mesh.tets[t]);
        for (int32_t v : mesh.tets[t]) local_index_[v] = 0;
    }
    for (size_t v = 0; v < local_index_.size(); ++v)
        if (local_index_[v] == 0) body_vertices_.push_back(static_cast<int32_t>(v));
    std::fill(local_index_.begin(), local_index_.end(), -1);
    for (size_t i = 0; i < body_vertices_.size(); ++i) local_index_[body_vertices_[i]] = static_cast<int32_t>(i);

    // B_t = S D_m^{-1}, with S mapping corner positions to the edge matrix [x1-x0, x2-x0, x3-x0].
    gradients_.resize(tets_.size());
    weights_.resize(tets_.size());
    std::atomic<bool> degenerate = false;
    for_rows(tets_.size(), kTetGrain, [&](size_t t) {
        const Tet& tet = tets_[t];
        Eigen::Matrix3d dm;
        for (int k = 0; k < 3; ++k) dm.col(k) = rest_[tet[k + 1]] - rest_[tet[0]];
        const double volume = dm.determinant() / 6.0;
        if (!(volume > 0)) {
            degenerate = true;
            return;
        }
        const Eigen::Matrix3d g = dm.inverse();
        Eigen::Matrix<double, 4, 3> b;
        b.row(0) = -g.colwise().sum();
        b.bottomRows<3>() = g;
        gradients_[t] = b;
        const double angle = min_dihedral_angle_deg(rest_[tet[0]], rest_[tet[1]], rest_[tet[2]], rest_[tet[3]]);
        weights_[t] = volume * std::max(1.0, kStiffSliverAngleDeg / angle);
    });
    if (degenerate) throw InvalidArgumentError("ARAP deformation: a tet of the body has non-positive volume");

    // Per body vertex: its (tet, corner) pairs as 4 t + corner, so the right-hand side is gathered
    // per vertex in parallel without write conflicts.
    std::vector<std::array<int32_t, 4>> local_tets(tets_.size());
    for (size_t t = 0; t < tets_.size(); ++t)
        for (int k = 0; k < 4; ++k) local_tets[t][k] = local_index_[tets_[t][k]];
    const CompressedRows rows = vertex_elements<4>(local_tets, body_vertices_.size());
    vertex_tets_.offsets = rows.offsets;
    vertex_tets_.indices.resize(rows.indices.size());
    for_rows(body_vertices_.size(), kVertexGrain, [&](size_t v) {
        for (int32_t i = rows.offsets[v]; i < rows.offsets[v + 1]; ++i) {
            const int32_t t = rows.indices[i];
            int corner = 0;
            while (local_tets[t][corner] != static_cast<int32_t>(v)) ++corner;
            vertex_tets_.indices[i] = 4 * t + corner;
        }
    });
    reset_rotations();  // the rest shape: every F_t = I
}

void ArapDeformer::reset_rotations() {
    rhs_shares_.resize(tets_.size());
    for_rows(tets_.size(), kTetGrain, [&](size_t t) { rhs_shares_[t] = weights_[t] * gradients_[t]; });
    rotations_current_ = true;
    energy_ = 0;
}

void ArapDeformer::set_constrained(std::vector<int32_t> constrained) {
    for (int32_t v : constrained)
        if (v < 0 || static_cast<size_t>(v) >= local_index_.size() || local_index_[v] < 0)
            throw InvalidArgumentError("ARAP deformation: constrained vertex " + std::to_string(v) +
                                       " is not a vertex of the body");
    if (constrained.empty())
        throw InvalidArgumentError("ARAP deformation: no vertex is constrained (the body could drift freely)");
    std::vector<int32_t> sorted_new = constrained, sorted_old = constrained_;
    std::sort(sorted_new.begin(), sorted_new.end());
    if (std::adjacent_find(sorted_new.begin(), sorted_new.end()) != sorted_new.end())
        throw InvalidArgumentError("ARAP deformation: a vertex is constrained twice");
    std::sort(sorted_old.begin(), sorted_old.end());
    const bool same_set = factor_ && sorted_new == sorted_old;
    constrained_ = std::move(constrained);
    if (same_set) return;

    const size_t n = body_vertices_.size();
    if (constrained_.size() >= n)
        throw InvalidArgumentError("ARAP deformation: every vertex of the body is constrained; nothing is left to deform");
    // Columns of K_fc are positions in constrained_ (the order of solve's targets).
    std::vector<int32_t> constrained_column(n, -1);
    for (size_t c = 0; c < constrained_.size(); ++c) constrained_column[local_index_[constrained_[c]]] = static_cast<int32_t>(c);
    free_index_.assign(n, -1);
    free_vertices_.clear();
    for (size_t v = 0; v < n; ++v)
        if (constrained_column[v] < 0) {
            free_index_[v] = static_cast<int32_t>(free_vertices_.size());
            free_vertices_.push_back(static_cast<int32_t>(v));
        }

    // K = sum_t vol_t B_t B_t^T (the cotangent Laplacian of Eq. 9), split into free and constrained.
    std::vector<Eigen::Triplet<double>> ff, fc;
    ff.reserve(tets_.size() * 10);
    for (size_t t = 0; t < tets_.size(); ++t) {
        const Eigen::Matrix4d k = weights_[t] * gradients_[t] * gradients_[t].transpose();
        for (int a = 0; a < 4; ++a) {
            const int32_t row = free_index_[local_index_[tets_[t][a]]];
            if (row < 0) continue;
            for (int b = 0; b < 4; ++b) {
                const int32_t lb = local_index_[tets_[t][b]];
                if (free_index_[lb] >= 0) {
                    if (free_index_[lb] <= row) ff.emplace_back(row, free_index_[lb], k(a, b));
                } else {
                    fc.emplace_back(row, constrained_column[lb], k(a, b));
                }
            }
        }
    }
    auto factor = std::make_unique<Factor>();
    Eigen::SparseMatrix<double> k_ff(static_cast<Eigen::Index>(free_vertices_.size()),
                                     static_cast<Eigen::Index>(free_vertices_.size()));
    k_ff.setFromTriplets(ff.begin(), ff.end());
    factor->k_fc.resize(static_cast<Eigen::Index>(free_vertices_.size()), static_cast<Eigen::Index>(constrained_.size()));
    factor->k_fc.setFromTriplets(fc.begin(), fc.end());
    if (!factor->compute(k_ff, options_.factor))
        throw AlgorithmError("ARAP deformation: the Cholesky factorisation of the stiffness matrix failed "
                             "(is a part of the body without a constrained vertex?)");
    factor_ = std::move(factor);
    ++factorizations_;
}

void ArapDeformer::local_step() {
    auto gradient = [&](size_t t) {
        const Tet& tet = tets_[t];
        Eigen::Matrix<double, 3, 4> x;
        for (int k = 0; k < 4; ++k) x.col(k) = positions_[tet[k]];
        return Eigen::Matrix3d(x * gradients_[t]);
    };
    if (options_.rotations == ArapRotations::Double) {
        energy_ = sum_rows(tets_.size(), kTetGrain, [&](size_t t) {
            const Eigen::Matrix3d f = gradient(t);
            const Eigen::Matrix3d r = nearest_rotation(f);
            rhs_shares_[t] = weights_[t] * gradients_[t] * r.transpose();
            return weights_[t] * (f - r).squaredNorm();
        });
    } else {
        const size_t batches = (tets_.size() + kLanes - 1) / kLanes;
        energy_ = sum_rows(batches, kTetGrain / kLanes, [&](size_t batch) {
            const size_t first = batch * kLanes;
            const int count = static_cast<int>(std::min<size_t>(kLanes, tets_.size() - first));
            std::array<Eigen::Matrix3d, kLanes> f, r;
            for (int l = 0; l < count; ++l) f[l] = gradient(first + l);
            const uint32_t fallback = nearest_rotations_float(f, count, r);
            double energy = 0;
            for (int l = 0; l < count; ++l) {
                const size_t t = first + l;
                if ((fallback >> l) & 1) r[l] = nearest_rotation(f[l]);
                rhs_shares_[t] = weights_[t] * gradients_[t] * r[l].transpose();
                energy += weights_[t] * (f[l] - r[l]).squaredNorm();
            }
            return energy;
        });
    }
    rotations_current_ = true;
}

void ArapDeformer::global_step(std::span<const Eigen::Vector3d> targets) {
    const size_t free_count = free_vertices_.size();
    Eigen::MatrixXd rhs(static_cast<Eigen::Index>(free_count), 3);
    // Right-hand side of Eq. 9 for the per-tet energy: row a = sum over tets t at a of vol_t B_t(a,:) R_t^T.
    for_rows(free_count, kVertexGrain, [&](size_t f) {
        const int32_t v = free_vertices_[f];
        Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
        for (int32_t i = vertex_tets_.offsets[v]; i < vertex_tets_.offsets[v + 1]; ++i) {
            const int32_t code = vertex_tets_.indices[i];
            const int32_t t = code / 4, corner = code % 4;
            sum += rhs_shares_[t].row(corner);
        }
        rhs.row(static_cast<Eigen::Index>(f)) = sum;
    });
    Eigen::MatrixXd constrained_positions(static_cast<Eigen::Index>(targets.size()), 3);
    for (size_t c = 0; c < targets.size(); ++c) constrained_positions.row(static_cast<Eigen::Index>(c)) = targets[c].transpose();
    rhs -= factor_->k_fc * constrained_positions;
    const Eigen::MatrixXd x = factor_->solve(rhs);
    for_rows(free_count, kVertexGrain, [&](size_t f) {
        positions_[body_vertices_[free_vertices_[f]]] = x.row(static_cast<Eigen::Index>(f)).transpose();
    });
    for (size_t c = 0; c < targets.size(); ++c) positions_[constrained_[c]] = targets[c];
    rotations_current_ = false;
}

ArapSolveReport ArapDeformer::solve(std::span<const Eigen::Vector3d> targets, int iterations) {
    if (!factor_) throw InvalidArgumentError("ARAP deformation: solve before any vertex is constrained");
    if (targets.size() != constrained_.size())
        throw InvalidArgumentError("ARAP deformation: " + std::to_string(targets.size()) + " targets for " +
                                   std::to_string(constrained_.size()) + " constrained vertices");
    if (iterations < 1) throw InvalidArgumentError("ARAP deformation: the iteration count must be >= 1");
    for (const Eigen::Vector3d& target : targets)
        if (!target.allFinite()) throw InvalidArgumentError("ARAP deformation: a target position is not finite");
    for (int i = 0; i < iterations; ++i) {
        if (!rotations_current_) local_step();
        global_step(targets);
    }
    // The rotations of the result: its energy now, and the next frame's first local step for free.
    local_step();
    return {iterations, energy_};
}

void ArapDeformer::set_positions(std::vector<Eigen::Vector3d> positions) {
    if (positions.size() != rest_.size())
        throw InvalidArgumentError("ARAP deformation: " + std::to_string(positions.size()) + " positions for " +
                                   std::to_string(rest_.size()) + " vertices");
    positions_ = std::move(positions);
    rotations_current_ = false;
}

void ArapDeformer::reset() {
    positions_ = rest_;
    reset_rotations();
}

double ArapDeformer::energy() const {
    if (rotations_current_) return energy_;
    return sum_rows(tets_.size(), kTetGrain, [&](size_t t) {
        Eigen::Matrix<double, 3, 4> x;
        for (int k = 0; k < 4; ++k) x.col(k) = positions_[tets_[t][k]];
        const Eigen::Matrix3d f = x * gradients_[t];
        return weights_[t] * (f - nearest_rotation(f)).squaredNorm();
    });
}

std::vector<int32_t> vertex_connected_tets(const TetMesh& mesh, const TetConnectivity& connectivity, int32_t seed) {
    if (seed < 0 || static_cast<size_t>(seed) >= mesh.vertex_count())
        throw InvalidArgumentError("vertex " + std::to_string(seed) + " out of range");
    std::vector<uint8_t> seen_vertex(mesh.vertex_count(), 0), seen_tet(mesh.tet_count(), 0);
    std::vector<int32_t> stack{seed}, tets;
    seen_vertex[seed] = 1;
    while (!stack.empty()) {
        const int32_t v = stack.back();
        stack.pop_back();
        for (int32_t t : connectivity.vertex_tets.row(v)) {
            if (seen_tet[t]) continue;
            seen_tet[t] = 1;
            tets.push_back(t);
            for (int32_t w : mesh.tets[t])
                if (!seen_vertex[w]) {
                    seen_vertex[w] = 1;
                    stack.push_back(w);
                }
        }
    }
    std::sort(tets.begin(), tets.end());
    return tets;
}

double handle_falloff(double distance, double radius) {
    if (!(distance < radius)) return 0;
    const double s = 1 - (distance / radius) * (distance / radius);
    return s * s;
}

std::vector<int32_t> DragRegion::constrained() const {
    std::vector<int32_t> all = handle;
    all.insert(all.end(), pinned.begin(), pinned.end());
    return all;
}

HandleMotion HandleMotion::translation(const Eigen::Vector3d& move) {
    HandleMotion m;
    m.move = move;
    return m;
}

HandleMotion HandleMotion::bend(const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction, double angle_rad) {
    HandleMotion m;
    m.kind = Kind::Bend;
    m.axis_point = axis_point;
    m.axis_direction = axis_direction;
    m.angle = angle_rad;
    return m;
}

HandleMotion HandleMotion::twist(const Eigen::Vector3d& axis_point, const Eigen::Vector3d& axis_direction,
                                 double angle_per_length) {
    HandleMotion m = bend(axis_point, axis_direction, angle_per_length);
    m.kind = Kind::Twist;
    return m;
}

HandleMotion HandleMotion::in_rest_frame(const RigidTransform& piece) const {
    HandleMotion m = *this;
    const Eigen::Matrix3d to_rest = piece.rotation.transpose();
    m.move = to_rest * move;
    m.axis_point = to_rest * (axis_point - piece.translation);
    m.axis_direction = to_rest * axis_direction;
    return m;
}

Eigen::Vector3d HandleMotion::apply(const Eigen::Vector3d& point, double f) const {
    if (kind == Kind::Translate) return point + f * move;
    const Eigen::Vector3d axis = axis_direction.normalized();
    const Eigen::Vector3d r = point - axis_point;
    const double turn = kind == Kind::Bend ? f * angle : f * angle * r.dot(axis);
    return axis_point + Eigen::AngleAxisd(turn, axis) * r;
}

void validate_handle_motion(const HandleMotion& motion) {
    if (!motion.move.allFinite()) throw InvalidArgumentError("the move is not finite");
    if (motion.kind == HandleMotion::Kind::Translate) return;
    if (!motion.axis_point.allFinite() || !motion.axis_direction.allFinite() || motion.axis_direction.norm() == 0)
        throw InvalidArgumentError("the rotation axis needs a finite point and a finite, non-zero direction");
    if (!std::isfinite(motion.angle))
        throw InvalidArgumentError(motion.kind == HandleMotion::Kind::Bend ? "the bend angle is not finite"
                                                                           : "the twist rate is not finite");
}

DragRegion select_drag_region(const TetMesh& mesh, const TetConnectivity& connectivity, const Eigen::Vector3d& grab,
                              double radius, const HandleMotion& motion, std::span<const PinSphere> pins) {
    if (!grab.allFinite()) throw InvalidArgumentError("the grab point is not finite");
    validate_handle_motion(motion);
    if (!(radius > 0) || !std::isfinite(radius))
        throw InvalidArgumentError("the handle radius must be a positive number");
    for (const PinSphere& pin : pins)
        if (!pin.center.allFinite() || !(pin.radius > 0) || !std::isfinite(pin.radius))
            throw InvalidArgumentError("a pin needs a finite centre and a positive radius");

    // World positions: each vertex through the transform of its piece (the piece of any of its tets).
    const size_t n = mesh.vertex_count();
    std::vector<int32_t> vertex_piece(n, -1);
    for (size_t v = 0; v < n; ++v) {
        const auto tets = connectivity.vertex_tets.row(v);
        if (!tets.empty()) vertex_piece[v] = mesh.piece_ids[tets.front()];
    }
    auto world = [&](size_t v) {
        const RigidTransform& x = mesh.piece_transforms[vertex_piece[v]];
        return Eigen::Vector3d(x.rotation * mesh.positions[v] + x.translation);
    };

    int32_t seed = -1;
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t v = 0; v < n; ++v) {
        if (vertex_piece[v] < 0) continue;
        const double d = (world(v) - grab).norm();
        if (handle_falloff(d, radius) >= kHandleMinWeight && d < nearest) {
            nearest = d;
            seed = static_cast<int32_t>(v);
        }
    }
    if (seed < 0)
        throw InvalidArgumentError("no vertex lies within the handle (distance <= " +
                                   std::to_string(radius * std::sqrt(1 - std::sqrt(kHandleMinWeight))) +
                                   ", i.e. 0.54 x radius, of " + point_text(grab) + ")");

    DragRegion region;
    region.piece = vertex_piece[seed];
    region.body_tets = vertex_connected_tets(mesh, connectivity, seed);
    std::vector<uint8_t> in_body(n, 0);
    for (int32_t t : region.body_tets)
        for (int32_t v : mesh.tets[t]) in_body[v] = 1;
    size_t body_vertices = 0, unpinned_handle = 0;
    for (size_t v = 0; v < n; ++v) {
        if (!in_body[v]) continue;
        ++body_vertices;
        const Eigen::Vector3d p = world(v);
        const bool pinned = std::any_of(pins.begin(), pins.end(),
                                        [&](const PinSphere& pin) { return (p - pin.center).norm() <= pin.radius; });
        const double w = handle_falloff((p - grab).norm(), radius);
        if (pinned) {
            region.pinned.push_back(static_cast<int32_t>(v));
        } else if (w >= kHandleMinWeight) {
            region.handle.push_back(static_cast<int32_t>(v));
            ++unpinned_handle;
        }
    }
    if (unpinned_handle == 0) throw InvalidArgumentError("every vertex of the handle is pinned");
    if (region.handle.size() + region.pinned.size() >= body_vertices)
        throw InvalidArgumentError("the handle and the pins hold every vertex of the body (" +
                                   std::to_string(body_vertices) + "); nothing is left to deform");
    region.motion_rest = motion.in_rest_frame(mesh.piece_transforms[region.piece]);
    return region;
}

std::vector<Eigen::Vector3d> drag_targets(const DragRegion& region, std::span<const Eigen::Vector3d> rest, double t) {
    std::vector<Eigen::Vector3d> targets;
    targets.reserve(region.handle.size() + region.pinned.size());
    for (const int32_t v : region.handle) targets.push_back(region.motion_rest.apply(rest[v], t));
    for (int32_t v : region.pinned) targets.push_back(rest[v]);
    return targets;
}

namespace {

std::vector<Eigen::Vector3d> moved_points(std::span<const Eigen::Vector3d> points, const HandleMotion& motion) {
    validate_handle_motion(motion);
    std::vector<Eigen::Vector3d> out;
    out.reserve(points.size());
    for (const Eigen::Vector3d& p : points) out.push_back(motion.apply(p, 1));
    return out;
}

}  // namespace

std::vector<Eigen::Vector3d> bend_about_axis(std::span<const Eigen::Vector3d> points, const Eigen::Vector3d& axis_point,
                                             const Eigen::Vector3d& axis_direction, double angle_rad) {
    return moved_points(points, HandleMotion::bend(axis_point, axis_direction, angle_rad));
}

std::vector<Eigen::Vector3d> twist_about_axis(std::span<const Eigen::Vector3d> points, const Eigen::Vector3d& axis_point,
                                              const Eigen::Vector3d& axis_direction, double angle_per_length) {
    return moved_points(points, HandleMotion::twist(axis_point, axis_direction, angle_per_length));
}

std::vector<double> guard_floors(std::span<const int32_t> tets, const std::vector<Tet>& mesh_tets,
                                 std::span<const Eigen::Vector3d> positions, const GuardOptions& options) {
    std::vector<double> floor_cosine(tets.size());
    for_rows(tets.size(), kTetGrain, [&](size_t i) {
        const Tet& tet = mesh_tets[tets[i]];
        const double before = min_dihedral_angle_deg(positions[tet[0]], positions[tet[1]], positions[tet[2]],
                                                     positions[tet[3]]);
        floor_cosine[i] = std::cos((std::min(options.min_dihedral_guard_deg, before) - 1e-9) * std::numbers::pi / 180);
    });
    return floor_cosine;
}

GuardedStep guard_step(const TetMesh& mesh, std::span<const int32_t> tets,
                       std::span<const Eigen::Vector3d> old_positions, std::span<const Eigen::Vector3d> new_positions,
                       const GuardOptions& options, std::span<const double> given_floor_cosine) {
    if (old_positions.size() != mesh.vertex_count() || new_positions.size() != mesh.vertex_count())
        throw InvalidArgumentError("guard_step: one old and one new position per vertex are needed");
    if (!(options.min_dihedral_guard_deg >= 0) || options.max_halvings < 0)
        throw InvalidArgumentError("guard_step: the guard must be >= 0 degrees and max_halvings >= 0");
    for (int32_t t : tets)
        if (t < 0 || static_cast<size_t>(t) >= mesh.tet_count())
            throw InvalidArgumentError("guard_step: tet index " + std::to_string(t) + " out of range");
    if (!given_floor_cosine.empty() && given_floor_cosine.size() != tets.size())
        throw InvalidArgumentError("guard_step: one floor per checked tet is needed");
    // Per tet, the least angle it may end with: the guard, or its own angle when it was already below.
    std::vector<double> computed_floor_cosine;
    if (given_floor_cosine.empty()) computed_floor_cosine = guard_floors(tets, mesh.tets, old_positions, options);
    const std::span<const double> floor_cosine =
        given_floor_cosine.empty() ? std::span<const double>(computed_floor_cosine) : given_floor_cosine;
    auto at = [&](int32_t v, double f) { return Eigen::Vector3d(old_positions[v] + f * (new_positions[v] - old_positions[v])); };
    // Per tet, the cosine of its smallest angle (2 for an inverted tet: below every angle).
    std::vector<double> cosine(tets.size());
    std::vector<uint8_t> failing(tets.size());
    auto check = [&](double f) {
        for_rows(tets.size(), kTetGrain, [&](size_t i) {
            const Tet& tet = mesh.tets[tets[i]];
            const Eigen::Vector3d a = at(tet[0], f), b = at(tet[1], f), c = at(tet[2], f), d = at(tet[3], f);
            cosine[i] = signed_volume(a, b, c, d) > 0 ? max_dihedral_cosine(a, b, c, d) : 2.0;
            failing[i] = cosine[i] > floor_cosine[i];
        });
        return std::count(failing.begin(), failing.end(), 1) == 0;
    };
    GuardedStep step;
    double fraction = 1;
    while (!check(fraction)) {
        if (step.halvings == options.max_halvings) {
            fraction = 0;
            check(0);
            break;
        }
        fraction *= 0.5;
        ++step.halvings;
    }
    step.fraction = fraction;
    step.inverted_tets = static_cast<size_t>(std::count(cosine.begin(), cosine.end(), 2.0));
    if (!tets.empty()) {
        // The smallest angle as min_dihedral_angle_deg gives it, or 0 when a tet is inverted.
        const double worst = *std::max_element(cosine.begin(), cosine.end());
        step.min_dihedral_deg = worst > 1 ? 0.0 : 180.0 - std::acos(-worst) * 180.0 / std::numbers::pi;
    }
    step.positions.assign(old_positions.begin(), old_positions.end());
    if (fraction > 0)
        for (int32_t t : tets)
            for (int32_t v : mesh.tets[t]) step.positions[v] = at(v, fraction);
    return step;
}

DragReport run_drag(ArapDeformer& deformer, const TetMesh& mesh, const DragRegion& region,
                    std::span<const Eigen::Vector3d> rest, int steps, int iterations, const GuardOptions& guard,
                    Progress* progress) {
    if (steps < 1) throw InvalidArgumentError("the drag needs at least one step");
    if (iterations < 1) throw InvalidArgumentError("the drag needs at least one iteration per step");
    report_stage(progress, "deforming (ARAP, " + std::to_string(steps) + " steps)");
    DragReport report;
    const auto factor_start = std::chrono::steady_clock::now();
    deformer.set_constrained(region.constrained());
    report.factorization_ms = milliseconds_since(factor_start);
    report.steps = steps;
    report.iterations_per_step = iterations;
    report.body_tets = region.body_tets.size();
    report.handle_vertices = region.handle.size();
    report.pinned_vertices = region.pinned.size();
    std::vector<Eigen::Vector3d> targets;
    for (int s = 1; s <= steps; ++s) {
        check_cancelled(progress);
        if (progress) progress->set_fraction(static_cast<float>(s - 1) / static_cast<float>(steps));
        targets = drag_targets(region, rest, static_cast<double>(s) / steps);
        const std::vector<Eigen::Vector3d> before = deformer.positions();
        report.energy = deformer.solve(targets, iterations).energy;
        GuardedStep step = guard_step(mesh, region.body_tets, before, deformer.positions(), guard);
        report.last_step_fraction = step.fraction;
        report.min_dihedral_deg = step.min_dihedral_deg;
        report.inverted_tets = step.inverted_tets;
        if (step.shortened()) {
            ++report.shortened_steps;
            deformer.set_positions(std::move(step.positions));
            report.energy = deformer.energy();
        }
    }
    const std::vector<int32_t> constrained = region.constrained();
    for (size_t c = 0; c < constrained.size(); ++c)
        report.handle_error = std::max(report.handle_error, (deformer.positions()[constrained[c]] - targets[c]).norm());
    return report;
}

}  // namespace waxwork
