#include "tetops/paint.h"

#include "base/error.h"

#include <nanoflann.hpp>
#include <tbb/parallel_for.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

namespace waxwork {
namespace {

// nanoflann reads points through this adaptor instead of copying them.
struct CentroidCloud {
    std::vector<Eigen::Vector3d> points;

    size_t kdtree_get_point_count() const { return points.size(); }
    double kdtree_get_pt(size_t index, size_t dim) const { return points[index][static_cast<int>(dim)]; }
    template <class BoundingBox>
    bool kdtree_get_bbox(BoundingBox&) const { return false; }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CentroidCloud>,
                                                   CentroidCloud, 3, uint32_t>;

void validate_brush(const PaintBrush& brush) {
    if (!(brush.sigma > 0) || !std::isfinite(brush.sigma))
        throw InvalidArgumentError("paint: sigma must be a positive number");
    if (!(brush.cutoff_weight > 0 && brush.cutoff_weight < 1))
        throw InvalidArgumentError("paint: the cutoff weight must be in (0, 1)");
    const TetMaterial& m = brush.material;
    bool valid = std::isfinite(m.eta) && m.eta > 0;
    for (int c = 0; c < 3; ++c)
        valid = valid && std::isfinite(m.mua[c]) && m.mua[c] >= 0 && std::isfinite(m.musp[c]) && m.musp[c] >= 0;
    if (!valid) throw InvalidArgumentError("paint: the brush material needs finite mu_a, mu_s' >= 0 and eta > 0");
}

}  // namespace

struct PaintIndex::Tree {
    CentroidCloud cloud;
    // Built after `cloud` is filled; holds a reference to it, so Tree lives on the heap and never moves.
    std::unique_ptr<KdTree> tree;
};

PaintIndex::PaintIndex(const TetMesh& mesh) : tree_(std::make_unique<Tree>()) {
    std::vector<Eigen::Vector3d>& centroids = tree_->cloud.points;
    centroids.resize(mesh.tet_count());
    const bool has_pieces = mesh.piece_ids.size() == mesh.tet_count();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, mesh.tet_count(), 4096), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) {
            const Tet& tet = mesh.tets[t];
            Eigen::Vector3d c = 0.25 * (mesh.positions[tet[0]] + mesh.positions[tet[1]] + mesh.positions[tet[2]] +
                                        mesh.positions[tet[3]]);
            if (has_pieces) {
                const int32_t piece = mesh.piece_ids[t];
                if (piece >= 0 && static_cast<size_t>(piece) < mesh.piece_transforms.size()) {
                    const RigidTransform& m = mesh.piece_transforms[piece];
                    c = m.rotation * c + m.translation;
                }
            }
            centroids[t] = c;
        }
    });
    tree_->tree = std::make_unique<KdTree>(3, tree_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
}

PaintIndex::~PaintIndex() = default;
PaintIndex::PaintIndex(PaintIndex&&) noexcept = default;
PaintIndex& PaintIndex::operator=(PaintIndex&&) noexcept = default;

size_t PaintIndex::tet_count() const { return tree_->cloud.points.size(); }
const std::vector<Eigen::Vector3d>& PaintIndex::centroids() const { return tree_->cloud.points; }

namespace {

// A nanoflann result set that folds every hit into a per-tet minimum instead of storing it: a stroke
// of 100 overlapping balls would otherwise produce each tet dozens of times. Non-negative doubles
// order like their bit patterns, so the minimum is an integer atomic min; the result does not depend
// on which thread gets there first. The first thread to lower a tet from "unseen" records it.
class NearestHits {
public:
    NearestHits(double radius_sq, std::vector<std::atomic<uint64_t>>& nearest, std::vector<uint32_t>& touched)
        : radius_sq_(radius_sq), nearest_(nearest), touched_(touched) {}

    bool full() const { return true; }
    double worstDist() const { return radius_sq_; }
    size_t size() const { return touched_.size(); }
    bool addPoint(double dist_sq, uint32_t tet) {
        if (!(dist_sq < radius_sq_)) return true;
        const uint64_t bits = std::bit_cast<uint64_t>(dist_sq);
        std::atomic<uint64_t>& slot = nearest_[tet];
        uint64_t current = slot.load(std::memory_order_relaxed);
        while (bits < current && !slot.compare_exchange_weak(current, bits, std::memory_order_relaxed)) {
        }
        if (current == kUnseen && bits < current) touched_.push_back(tet);
        return true;
    }

    static constexpr uint64_t kUnseen = ~uint64_t{0};

private:
    double radius_sq_;
    std::vector<std::atomic<uint64_t>>& nearest_;
    std::vector<uint32_t>& touched_;
};

}  // namespace

std::vector<std::pair<uint32_t, double>> PaintIndex::nearest_within(std::span<const Eigen::Vector3d> stroke,
                                                                    double radius) const {
    std::vector<std::pair<uint32_t, double>> result;
    if (tet_count() == 0 || stroke.empty()) return result;
    std::vector<std::atomic<uint64_t>> nearest(tet_count());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nearest.size(), 16384), [&](const auto& range) {
        for (size_t t = range.begin(); t != range.end(); ++t) nearest[t].store(NearestHits::kUnseen, std::memory_order_relaxed);
    });
    tbb::enumerable_thread_specific<std::vector<uint32_t>> touched;
    tbb::parallel_for(size_t{0}, stroke.size(), [&](size_t i) {
        NearestHits hits(radius * radius, nearest, touched.local());
        tree_->tree->findNeighbors(hits, stroke[i].data(), nanoflann::SearchParams());
    });
    for (const std::vector<uint32_t>& part : touched)
        for (uint32_t t : part) result.emplace_back(t, std::bit_cast<double>(nearest[t].load(std::memory_order_relaxed)));
    std::sort(result.begin(), result.end());
    return result;
}

double paint_radius(const PaintBrush& brush) { return brush.sigma * std::sqrt(-2.0 * std::log(brush.cutoff_weight)); }

PaintResult paint_stroke(TetMesh& mesh, const PaintIndex& index, std::span<const Eigen::Vector3d> stroke,
                         const PaintBrush& brush, const std::optional<TetMaterial>& base) {
    validate_brush(brush);
    if (stroke.empty()) throw InvalidArgumentError("paint: the stroke has no points");
    for (const Eigen::Vector3d& p : stroke)
        if (!p.allFinite()) throw InvalidArgumentError("paint: a stroke point is not finite");
    if (index.tet_count() != mesh.tet_count())
        throw InvalidArgumentError("paint: the paint index was built for a different mesh (rebuild it after a cut)");
    // An empty mesh (everything cut away) has nothing to paint and needs no base material.
    if (!mesh.has_materials() && mesh.tet_count() > 0) {
        if (!base) throw InvalidArgumentError("paint: the volume has no materials; a base material is needed");
        mesh.materials.assign(mesh.tet_count(), *base);
    }

    // Slightly beyond the cutoff radius so rounding cannot lose a tet whose weight is exactly at the
    // cutoff; the weight test below decides.
    const double radius = paint_radius(brush) * (1.0 + 1e-9);
    const std::vector<std::pair<uint32_t, double>> hits = index.nearest_within(stroke, radius);

    PaintResult result;
    const double two_sigma2 = 2.0 * brush.sigma * brush.sigma;
    for (size_t i = 0; i < hits.size(); ++i) {
        const double w = std::exp(-hits[i].second / two_sigma2);
        if (w < brush.cutoff_weight) continue;
        result.changed_tets.push_back(static_cast<int32_t>(hits[i].first));
        result.weights.push_back(w);
    }

    tbb::parallel_for(size_t{0}, result.changed_tets.size(), [&](size_t i) {
        TetMaterial& m = mesh.materials[result.changed_tets[i]];
        const double w = result.weights[i];
        for (int c = 0; c < 3; ++c) {
            m.mua[c] = (1 - w) * m.mua[c] + w * brush.material.mua[c];
            m.musp[c] = (1 - w) * m.musp[c] + w * brush.material.musp[c];
        }
        m.eta = (1 - w) * m.eta + w * brush.material.eta;
    });
    return result;
}

PaintResult paint_stroke(TetMesh& mesh, std::span<const Eigen::Vector3d> stroke, const PaintBrush& brush,
                         const std::optional<TetMaterial>& base) {
    validate_brush(brush);  // before the index is built: a bad brush should fail fast
    const PaintIndex index(mesh);
    return paint_stroke(mesh, index, stroke, brush, base);
}

}  // namespace waxwork
