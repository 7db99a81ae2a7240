#include "scene/document.h"

#include "base/error.h"
#include "base/timing.h"
#include "tetops/cut.h"
#include "tetops/exact_cut.h"
#include "tetops/fracture.h"
#include "tetops/fragments.h"
#include "tetops/paint.h"
#include "tetops/quality.h"
#include "tetops/refine.h"
#include "tetops/relaxation.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <sstream>

namespace waxwork {
namespace {

double min_dihedral_of(const TetMesh& mesh) {
    const std::vector<double> angles = min_dihedral_angles_deg(mesh);
    return angles.empty() ? 0.0 : *std::min_element(angles.begin(), angles.end());
}

template <typename T>
size_t vector_bytes(const std::vector<T>& v) {
    return v.capacity() * sizeof(T);
}

size_t mesh_bytes(const TetMesh& m) {
    return sizeof(TetMesh) + vector_bytes(m.positions) + vector_bytes(m.tets) + vector_bytes(m.materials) +
           vector_bytes(m.original_ids) + vector_bytes(m.piece_ids) + vector_bytes(m.piece_transforms);
}

std::unique_ptr<CuttingSurface> make_surface(const std::variant<PlaneSurface, StrokeSurface>& surface) {
    if (const auto* p = std::get_if<PlaneSurface>(&surface)) return std::make_unique<PlaneCut>(p->normal, p->offset);
    const auto& s = std::get<StrokeSurface>(surface);
    return std::make_unique<StrokeCut>(s.eye, s.view_direction, s.points, s.flip);
}

// The counts of a tetops result without its arrays (OperationResult).
CutResult without_arrays(CutResult r) {
    r.old_to_new_vertex = {};
    r.new_to_old_tet = {};
    return r;
}
ExactCutResult without_arrays(ExactCutResult r) {
    r.new_to_old_tet = {};
    r.vertex_origins = {};
    return r;
}
FractureResult without_arrays(FractureResult r) {
    r.vertex_origins = {};
    return r;
}
WeldResult without_arrays(WeldResult r) {
    r.old_to_new_vertex = {};
    return r;
}
FragmentRemoval without_arrays(FragmentRemoval r) {
    r.removed = without_arrays(std::move(r.removed));
    return r;
}
RefineResult without_arrays(RefineResult r) {
    r.new_to_old_tet = {};
    r.vertex_origins = {};
    return r;
}
PaintResult without_arrays(PaintResult r) {
    r.changed_tets = {};
    r.weights = {};
    return r;
}

RelaxationOptions relaxation_options(const RelaxSettings& r) {
    RelaxationOptions o;
    o.max_iterations = r.iterations;
    o.step = r.step;
    o.min_dihedral_guard_deg = r.guard_deg;
    return o;
}

}  // namespace

struct Document::DeformCache {
    std::shared_ptr<const TetConnectivity> connectivity;  // of the current topology
    // The last deform's handle and what was built for it, valid while the positions equal `rest`.
    Eigen::Vector3d grab = Eigen::Vector3d::Zero();
    double radius = 0;
    std::vector<PinSphere> pins;
    std::vector<Eigen::Vector3d> rest;
    DragRegion region;
    std::optional<ArapDeformer> deformer;
    bool previewing = false;  // a drag is shown: the mesh holds preview positions, `rest` the ones before
    std::vector<double> guard_floors;  // while previewing: per body tet, guard_floors (cosines) at `rest`
    double guard_deg = 0;              // ... for this guard
};

Document::Document(TetMesh mesh, const TetMaterial& default_material, size_t undo_budget_bytes)
    : mesh_(std::move(mesh)), budget_(undo_budget_bytes) {
    validate(mesh_);
    if (!mesh_.has_materials()) mesh_.materials.assign(mesh_.tet_count(), default_material);
    min_dihedral_deg_ = min_dihedral_of(mesh_);
}

Document::~Document() = default;
Document::Document(Document&&) noexcept = default;
Document& Document::operator=(Document&&) noexcept = default;

Document::DeformCache& Document::deform_setup(const DeformOp& op) {
    if (!deform_cache_) deform_cache_ = std::make_unique<DeformCache>();
    DeformCache& c = *deform_cache_;
    if (!c.connectivity) c.connectivity = std::make_shared<const TetConnectivity>(build_connectivity(mesh_));
    DragRegion region;
    try {
        region = select_drag_region(mesh_, *c.connectivity, op.grab, op.radius, op.motion, op.pins);
    } catch (const InvalidArgumentError& error) {
        throw InvalidArgumentError(std::string("deform: ") + error.what());
    }
    // A new body or rest shape changes the gradient operators and K: build them again. The same ones
    // with another handle or pins only refactor (ArapDeformer::set_constrained decides).
    if (!c.deformer || region.body_tets != c.region.body_tets || c.rest != mesh_.positions) {
        c.deformer.reset();
        c.deformer.emplace(mesh_, region.body_tets);
        c.rest = mesh_.positions;
    }
    c.region = std::move(region);
    c.grab = op.grab;
    c.radius = op.radius;
    c.pins = op.pins;
    return c;
}

bool Document::previewing() const { return deform_cache_ && deform_cache_->previewing; }

void Document::require_no_preview(const char* what) const {
    if (previewing())
        throw InvalidArgumentError(std::string(what) + ": a deform drag is in progress (commit or cancel it first)");
}

ChangeReport Document::run(const EditOperation& op, UndoEntry& entry, Progress* progress) {
    const auto start = std::chrono::steady_clock::now();
    ChangeReport report;
    report.name = operation_name(op);
    report.tets_before = mesh_.tet_count();
    report.vertices_before = mesh_.vertex_count();
    entry.op = op;
    entry.old_min_dihedral_deg = min_dihedral_deg_;
    std::ostringstream details;
    // Relax and deform: the vertices whose position changed, their old positions for undo.
    const auto record_moved_vertices = [&](const std::vector<Eigen::Vector3d>& before,
                                           const std::vector<Eigen::Vector3d>& after) {
        for (size_t v = 0; v < before.size(); ++v) {
            if (before[v] != after[v]) {
                entry.moved_vertices.push_back(static_cast<int32_t>(v));
                entry.old_positions.push_back(before[v]);
            }
        }
        report.positions = !entry.moved_vertices.empty();
        report.moved_vertices = entry.moved_vertices;
    };

    // Cut: remove the tets on the cut-away side, then relax the cut vertices onto the surface
    // (TransCut Sec. 5), or split the crossed tets exactly along it. Works on a copy that becomes the mesh only when everything succeeded; the
    // old mesh becomes the undo snapshot, so the copy costs nothing extra.
    const auto cut = [&](const std::variant<PlaneSurface, StrokeSurface>& spec, const RelaxSettings& relax,
                         bool exact) {
        const std::unique_ptr<CuttingSurface> surface = make_surface(spec);
        auto after = std::make_shared<TetMesh>(mesh_);
        std::shared_ptr<TetConnectivity> connectivity;
        if (exact) {
            // Crossed tets are split along the surface (tetops/exact_cut.h): nothing is left on the
            // cut-away side, so there is nothing to relax.
            ExactCutResult result = cut_exact(*after, *surface);
            require_tets_left_by_cut(*after, mesh_.tet_count());
            connectivity = std::make_shared<TetConnectivity>(build_connectivity(*after));
            min_dihedral_deg_ = result.min_dihedral_deg;
            // Kept vertices (origin: vertex v) give the map both ways; vertices made on edges have none.
            entry.snapshot_vertex.resize(result.vertex_origins.size());
            report.old_to_new_vertex.assign(mesh_.vertex_count(), -1);
            for (size_t v = 0; v < result.vertex_origins.size(); ++v) {
                const VertexOrigin& origin = result.vertex_origins[v];
                entry.snapshot_vertex[v] = origin.is_vertex() ? origin.a : -1;
                if (origin.is_vertex()) report.old_to_new_vertex[static_cast<size_t>(origin.a)] = static_cast<int32_t>(v);
            }
            report.vertex_origins = std::move(result.vertex_origins);
            report.tets_under_guard = result.tets_under_guard;
            details << result.tets_split << " tets split, " << result.tets_removed << " tets removed, "
                    << result.vertices_snapped << " vertices snapped onto the surface, " << result.tets_under_guard
                    << " tets under the angle guard";
            report.result = without_arrays(std::move(result));
        } else {
            CutResult removed = remove_cut_away_tets(*after, *surface);
            require_tets_left_by_cut(*after, mesh_.tet_count());
            connectivity = std::make_shared<TetConnectivity>(build_connectivity(*after));
            const RelaxationReport relaxed =
                relax_cut_vertices(*after, *connectivity, *surface, relaxation_options(relax));
            min_dihedral_deg_ = relaxed.min_dihedral_deg;
            entry.snapshot_vertex = inverse_vertex_map(removed.old_to_new_vertex, after->vertex_count());
            report.old_to_new_vertex = std::move(removed.old_to_new_vertex);
            details << removed.tets_removed << " tets removed, " << relaxed.vertices_moved
                    << " vertices relaxed (" << relaxed.iterations << " sweeps, " << relaxed.moves_rejected
                    << " moves rejected by the guard)";
            report.result = RelaxedCutResult{without_arrays(std::move(removed)), relaxed};
        }
        // A cut of a concave shape can leave specks floating: say so, and what drops them.
        const FragmentSurvey fragments = survey_fragments(*after, *connectivity, kDefaultFragmentFraction);
        if (fragments.small_parts > 0)
            details << "; left " << fragments.small_parts << " detached "
                    << (fragments.small_parts == 1 ? "part" : "parts") << " under " << 100 * kDefaultFragmentFraction
                    << "% of the volume (" << fragments.small_part_tets << " tets; Edit > Remove fragments drops them)";
        entry.snapshot = std::make_shared<const TetMesh>(std::move(mesh_));
        mesh_ = std::move(*after);
        report.topology = true;
        report.connectivity = std::move(connectivity);
    };

    if (const auto* o = std::get_if<PlaneCutOp>(&op)) {
        cut(o->plane, o->relax, o->exact);
    } else if (const auto* o = std::get_if<StrokeCutOp>(&op)) {
        cut(o->stroke, o->relax, o->exact);
    } else if (const auto* o = std::get_if<RelaxOp>(&op)) {
        const std::unique_ptr<CuttingSurface> surface = make_surface(o->surface);
        const std::vector<Eigen::Vector3d> before = mesh_.positions;
        const TetConnectivity connectivity = build_connectivity(mesh_);
        // relax_cut_vertices validates its options before moving anything, and a move is applied only
        // after its whole star passed: an exception leaves `before` to restore.
        RelaxationReport relaxed;
        try {
            relaxed = relax_cut_vertices(mesh_, connectivity, *surface, relaxation_options(o->relax));
        } catch (...) {
            mesh_.positions = before;
            throw;
        }
        record_moved_vertices(before, mesh_.positions);
        min_dihedral_deg_ = relaxed.min_dihedral_deg;
        report.connectivity = std::make_shared<const TetConnectivity>(connectivity);
        details << entry.moved_vertices.size() << " vertices moved in " << relaxed.iterations << " sweeps";
        report.result = relaxed;
    } else if (const auto* o = std::get_if<DeformOp>(&op)) {
        DeformCache& c = deform_setup(*o);
        GuardOptions guard;
        guard.min_dihedral_guard_deg = o->guard_deg;
        c.deformer->reset();  // from the rest shape, as a fresh deformer: the result depends on `op` only
        c.deformer->set_rotations(ArapRotations::Double);  // a preview may have left it in float
        const DragReport drag =
            run_drag(*c.deformer, mesh_, c.region, mesh_.positions, o->steps, o->iterations, guard, progress);
        record_moved_vertices(mesh_.positions, c.deformer->positions());
        mesh_.positions = c.deformer->positions();
        min_dihedral_deg_ = min_dihedral_of(mesh_);
        report.connectivity = c.connectivity;
        details << entry.moved_vertices.size() << " vertices moved in " << drag.steps << " steps of "
                << drag.iterations_per_step << " iterations";
        if (drag.shortened_steps > 0)
            details << "; the angle guard shortened " << drag.shortened_steps << (drag.shortened_steps == 1 ? " step" : " steps");
        report.result = drag;
    } else if (const auto* o = std::get_if<PaintOp>(&op)) {
        PaintBrush brush;
        brush.material = o->material;
        brush.sigma = o->sigma;
        brush.cutoff_weight = o->cutoff_weight;
        if (!(brush.sigma > 0)) throw InvalidArgumentError("paint: sigma must be a positive number");
        if (!paint_index_) paint_index_ = std::make_shared<PaintIndex>(mesh_);
        // Every tet the brush can reach, saved before painting: the changed tets are among them.
        const auto candidates = paint_index_->nearest_within(o->points, paint_radius(brush));
        std::vector<TetMaterial> old(candidates.size());
        for (size_t i = 0; i < candidates.size(); ++i) old[i] = mesh_.materials[candidates[i].first];
        PaintResult painted = paint_stroke(mesh_, *paint_index_, o->points, brush);
        // Both lists ascend: merge to keep the old materials of the changed tets only.
        size_t i = 0;
        for (const int32_t t : painted.changed_tets) {
            while (i < candidates.size() && static_cast<int32_t>(candidates[i].first) < t) ++i;
            if (i == candidates.size() || static_cast<int32_t>(candidates[i].first) != t)
                throw AlgorithmError("paint changed tet " + std::to_string(t) + " outside the brush radius");
            entry.material_tets.push_back(t);
            entry.old_materials.push_back(old[i]);
        }
        report.changed_material_tets = std::move(painted.changed_tets);
        details << report.changed_material_tets.size() << " tets painted";
        report.result = without_arrays(std::move(painted));
    } else if (const auto* o = std::get_if<SetMaterialOp>(&op)) {
        if (o->piece && (*o->piece < 0 || static_cast<size_t>(*o->piece) >= mesh_.piece_transforms.size()))
            throw InvalidArgumentError("set_material: piece " + std::to_string(*o->piece) + " does not exist (" +
                                       std::to_string(mesh_.piece_transforms.size()) + " pieces)");
        for (size_t t = 0; t < mesh_.tet_count(); ++t) {
            if (o->piece && mesh_.piece_ids[t] != *o->piece) continue;
            if (mesh_.materials[t] == o->material) continue;
            entry.material_tets.push_back(static_cast<int32_t>(t));
            entry.old_materials.push_back(mesh_.materials[t]);
            mesh_.materials[t] = o->material;
        }
        report.changed_material_tets = entry.material_tets;
        details << report.changed_material_tets.size() << " tets changed";
    } else if (const auto* o = std::get_if<RefineOp>(&op)) {
        // Bisection only appends vertices: each vertex before keeps its index, so the maps are identities.
        auto after = std::make_shared<TetMesh>(mesh_);
        RefineOptions options;
        options.max_tets = o->max_tets;
        options.guard_deg = o->guard_deg;
        RefineResult result = o->points.empty()
                                  ? refine_tets(*after, o->tets, options, progress)
                                  : refine_near_points(*after, o->points, o->radius, o->edge_length, options, progress);
        if (result.bisections > 0)
            adopt_appended(std::move(*after), std::move(result.vertex_origins), result.min_dihedral_deg, entry, report);
        details << result.marks_refined << " of " << result.marks << " marked tets refined, " << result.bisections
                << " bisections";
        if (result.marks_skipped_guard > 0) details << ", " << result.marks_skipped_guard << " skipped by the angle guard";
        if (result.marks_skipped_budget > 0) details << ", " << result.marks_skipped_budget << " left by the budget";
        report.result = without_arrays(std::move(result));
    } else if (const auto* o = std::get_if<RemoveFragmentsOp>(&op)) {
        auto after = std::make_shared<TetMesh>(mesh_);
        FragmentRemoval removal = remove_small_fragments(*after, o->max_volume_fraction);
        if (removal.fragments_removed > 0) {
            entry.snapshot_vertex = inverse_vertex_map(removal.removed.old_to_new_vertex, after->vertex_count());
            report.old_to_new_vertex = std::move(removal.removed.old_to_new_vertex);
            entry.snapshot = std::make_shared<const TetMesh>(std::move(mesh_));
            mesh_ = std::move(*after);
            min_dihedral_deg_ = min_dihedral_of(mesh_);
            report.topology = true;
        }
        details << removal.fragments_removed << " fragments removed (" << removal.removed.tets_removed << " tets), "
                << removal.parts_kept << (removal.parts_kept == 1 ? " part" : " parts") << " kept";
        report.result = without_arrays(std::move(removal));
    } else {
        run_piece_operation(op, entry, report, details);
    }

    if (report.topology || report.positions || report.piece_transforms) paint_index_.reset();
    if (report.topology) deform_cache_.reset();
    report.tets_after = mesh_.tet_count();
    report.vertices_after = mesh_.vertex_count();
    report.min_dihedral_deg = min_dihedral_deg_;
    report.details = details.str();
    entry.bytes = sizeof(UndoEntry) + vector_bytes(entry.material_tets) + vector_bytes(entry.old_materials) +
                  vector_bytes(entry.moved_vertices) + vector_bytes(entry.old_positions) +
                  vector_bytes(entry.snapshot_vertex) +
                  (entry.snapshot ? mesh_bytes(*entry.snapshot) : 0);
    report.milliseconds = milliseconds_since(start);
    return report;
}

void Document::push_undo(UndoEntry entry, ChangeReport& report) {
    if (entry.bytes > budget_) {
        // Keeping it would mean dropping every other entry and still exceeding the budget.
        report.undo_entries_evicted = undo_.size();
        evicted_ += undo_.size();
        undo_.clear();
        undo_bytes_ = 0;
        report.undoable = false;
        return;
    }
    while (!undo_.empty() && undo_bytes_ + entry.bytes > budget_) {
        undo_bytes_ -= undo_.front().bytes;
        undo_.pop_front();
        ++evicted_;
        ++report.undo_entries_evicted;
    }
    undo_bytes_ += entry.bytes;
    undo_.push_back(std::move(entry));
}

ChangeReport Document::apply(const EditOperation& op, Progress* progress) {
    require_no_preview(operation_name(op).c_str());
    UndoEntry entry;
    ChangeReport report = run(op, entry, progress);
    redo_.clear();
    history_.push_back(op);
    push_undo(std::move(entry), report);
    return report;
}

std::optional<ChangeReport> Document::undo() {
    require_no_preview("undo");
    if (undo_.empty()) return std::nullopt;
    const auto start = std::chrono::steady_clock::now();
    UndoEntry entry = std::move(undo_.back());
    undo_.pop_back();
    undo_bytes_ -= entry.bytes;
    ChangeReport report;
    report.name = "undo " + operation_name(entry.op);
    report.tets_before = mesh_.tet_count();
    report.vertices_before = mesh_.vertex_count();
    if (entry.snapshot) {
        if (entry.snapshot_vertex.size() == mesh_.vertex_count()) report.old_to_new_vertex = std::move(entry.snapshot_vertex);
        mesh_ = *entry.snapshot;
        report.topology = true;
    } else if (entry.piece >= 0) {
        mesh_.piece_transforms[entry.piece] = entry.old_transform;
        report.piece_transforms = true;
    } else if (!entry.moved_vertices.empty()) {
        for (size_t i = 0; i < entry.moved_vertices.size(); ++i)
            mesh_.positions[entry.moved_vertices[i]] = entry.old_positions[i];
        report.positions = true;
        report.moved_vertices = std::move(entry.moved_vertices);
    } else {
        for (size_t i = 0; i < entry.material_tets.size(); ++i)
            mesh_.materials[entry.material_tets[i]] = entry.old_materials[i];
        report.changed_material_tets = entry.material_tets;
    }
    if (report.topology || report.positions || report.piece_transforms) paint_index_.reset();
    if (report.topology) deform_cache_.reset();
    min_dihedral_deg_ = entry.old_min_dihedral_deg;
    report.min_dihedral_deg = min_dihedral_deg_;
    report.tets_after = mesh_.tet_count();
    report.vertices_after = mesh_.vertex_count();
    redo_.push_back(std::move(entry.op));
    history_.pop_back();
    report.milliseconds = milliseconds_since(start);
    return report;
}

std::optional<ChangeReport> Document::redo() {
    require_no_preview("redo");
    if (redo_.empty()) return std::nullopt;
    UndoEntry entry;
    ChangeReport report = run(redo_.back(), entry);
    report.name = "redo " + report.name;
    history_.push_back(redo_.back());
    redo_.pop_back();
    push_undo(std::move(entry), report);
    return report;
}

namespace {

// The vertices whose position differs between `shown` and `now`, ascending.
std::vector<int32_t> changed_positions(const std::vector<Eigen::Vector3d>& shown, const std::vector<Eigen::Vector3d>& now) {
    std::vector<int32_t> moved;
    for (size_t v = 0; v < now.size(); ++v)
        if (shown[v] != now[v]) moved.push_back(static_cast<int32_t>(v));
    return moved;
}

}  // namespace

ChangeReport Document::preview_deform(const DeformOp& op, int iterations) {
    const auto start = std::chrono::steady_clock::now();
    if (iterations < 1 || iterations > kMaxDeformIterations)
        throw InvalidArgumentError("deform preview: iterations must be between 1 and " +
                                   std::to_string(kMaxDeformIterations));
    if (!previewing()) {
        DeformCache& c = deform_setup(op);
        c.deformer->reset();
        c.deformer->set_constrained(c.region.constrained());
        GuardOptions guard;
        guard.min_dihedral_guard_deg = op.guard_deg;
        c.guard_floors = guard_floors(c.region.body_tets, mesh_.tets, c.rest, guard);
        c.guard_deg = op.guard_deg;
        c.previewing = true;
    } else {
        const DeformCache& c = *deform_cache_;
        if (op.grab != c.grab || op.radius != c.radius || op.pins != c.pins || op.guard_deg != c.guard_deg)
            throw InvalidArgumentError("deform preview: a drag keeps its grab point, radius, pins and guard");
        validate_handle_motion(op.motion);
    }
    DeformCache& c = *deform_cache_;
    // The preview's rotations in float (ArapRotations); the release commits from the rest shape in double.
    c.deformer->set_rotations(ArapRotations::Float);
    c.region.motion_rest = op.motion.in_rest_frame(mesh_.piece_transforms[c.region.piece]);
    GuardOptions guard;
    guard.min_dihedral_guard_deg = op.guard_deg;
    const std::vector<Eigen::Vector3d> targets = drag_targets(c.region, c.rest, 1.0);
    const std::vector<Eigen::Vector3d> before = c.deformer->positions();
    DragReport drag;
    drag.steps = 1;
    drag.iterations_per_step = iterations;
    drag.body_tets = c.region.body_tets.size();
    drag.handle_vertices = c.region.handle.size();
    drag.pinned_vertices = c.region.pinned.size();
    drag.energy = c.deformer->solve(targets, iterations).energy;
    GuardedStep step = guard_step(mesh_, c.region.body_tets, before, c.deformer->positions(), guard, c.guard_floors);
    drag.last_step_fraction = step.fraction;
    drag.min_dihedral_deg = step.min_dihedral_deg;
    drag.inverted_tets = step.inverted_tets;
    if (step.shortened()) {
        drag.shortened_steps = 1;
        c.deformer->set_positions(std::move(step.positions));
        drag.energy = c.deformer->energy();
    }
    ChangeReport report;
    report.name = "deform preview";
    report.tets_before = report.tets_after = mesh_.tet_count();
    report.vertices_before = report.vertices_after = mesh_.vertex_count();
    for (const int32_t v : c.deformer->body_vertices()) {
        if (mesh_.positions[v] == c.deformer->positions()[v]) continue;
        report.moved_vertices.push_back(v);
        mesh_.positions[v] = c.deformer->positions()[v];
    }
    report.positions = !report.moved_vertices.empty();
    if (report.positions) paint_index_.reset();
    report.connectivity = c.connectivity;
    report.min_dihedral_deg = min_dihedral_deg_;
    report.undoable = false;
    report.result = drag;
    report.milliseconds = milliseconds_since(start);
    return report;
}

ChangeReport Document::commit_deform(const DeformOp& op) {
    if (!previewing()) throw InvalidArgumentError("deform: no drag in progress to commit");
    DeformCache& c = *deform_cache_;
    std::vector<Eigen::Vector3d> shown = c.rest;
    std::swap(shown, mesh_.positions);  // the positions before the drag are what `op` applies to
    c.previewing = false;
    ChangeReport report;
    try {
        report = apply(op);
    } catch (...) {
        // The drag goes on as it was shown: the caller may cancel it.
        mesh_.positions = std::move(shown);
        c.previewing = true;
        throw;
    }
    report.moved_vertices = changed_positions(shown, mesh_.positions);
    report.positions = !report.moved_vertices.empty();
    return report;
}

std::optional<ChangeReport> Document::cancel_deform() {
    if (!previewing()) return std::nullopt;
    const auto start = std::chrono::steady_clock::now();
    DeformCache& c = *deform_cache_;
    ChangeReport report;
    report.name = "cancel deform";
    report.tets_before = report.tets_after = mesh_.tet_count();
    report.vertices_before = report.vertices_after = mesh_.vertex_count();
    report.moved_vertices = changed_positions(mesh_.positions, c.rest);
    report.positions = !report.moved_vertices.empty();
    mesh_.positions = c.rest;
    c.previewing = false;
    if (report.positions) paint_index_.reset();
    report.connectivity = c.connectivity;
    report.min_dihedral_deg = min_dihedral_deg_;
    report.milliseconds = milliseconds_since(start);
    return report;
}

void Document::adopt_appended(TetMesh after, std::vector<VertexOrigin> origins, double min_dihedral_deg,
                              UndoEntry& entry, ChangeReport& report) {
    report.old_to_new_vertex.resize(mesh_.vertex_count());
    std::iota(report.old_to_new_vertex.begin(), report.old_to_new_vertex.end(), 0);
    entry.snapshot_vertex = inverse_vertex_map(report.old_to_new_vertex, after.vertex_count());
    report.vertex_origins = std::move(origins);
    entry.snapshot = std::make_shared<const TetMesh>(std::move(mesh_));
    mesh_ = std::move(after);
    min_dihedral_deg_ = min_dihedral_deg;
    report.topology = true;
}

// Fracture, piece moves and welds (tetops/fracture.h).
void Document::run_piece_operation(const EditOperation& op, UndoEntry& entry, ChangeReport& report,
                                   std::ostringstream& details) {
    if (const auto* o = std::get_if<FractureOp>(&op)) {
        const std::vector<Eigen::Vector3d> seeds =
            o->seeds.empty() ? scatter_fracture_seeds(mesh_, o->pieces, o->seed) : o->seeds;
        FractureOptions options;
        options.exact = o->exact;
        options.min_piece_tets = o->min_piece_tets;
        options.collapse_swallowed_walls = o->collapse;
        auto after = std::make_shared<TetMesh>(mesh_);
        FractureResult result = fracture_voronoi(*after, seeds, options);
        // Vertices before keep their index; the fracture only appends.
        adopt_appended(std::move(*after), std::move(result.vertex_origins), result.min_dihedral_deg, entry, report);
        report.tets_under_guard = result.tets_under_guard;
        details << result.pieces_before << " -> " << result.pieces_after << " pieces, " << result.tets_split
                << " tets split, " << result.vertices_collapsed << " vertices of swallowed walls collapsed, "
                << result.vertices_duplicated << " crack vertices duplicated, "
                << result.tets_under_guard << " tets under the angle guard";
        report.result = without_arrays(std::move(result));
    } else if (const auto* o = std::get_if<MovePieceOp>(&op)) {
        if (o->piece < 0 || static_cast<size_t>(o->piece) >= mesh_.piece_transforms.size())
            throw InvalidArgumentError("move_piece: piece " + std::to_string(o->piece) + " does not exist (" +
                                       std::to_string(mesh_.piece_transforms.size()) + " pieces)");
        entry.piece = o->piece;
        entry.old_transform = mesh_.piece_transforms[o->piece];
        set_piece_transform(mesh_, o->piece, o->transform);
        report.piece_transforms = true;
        details << "piece " << o->piece << " moved";
    } else if (const auto* o = std::get_if<WeldOp>(&op)) {
        auto after = std::make_shared<TetMesh>(mesh_);
        WeldResult result = weld_touching_pieces(*after, o->tolerance);
        if (result.vertices_merged > 0 || result.pieces_after != result.pieces_before || !(*after == mesh_)) {
            if (result.old_to_new_vertex.size() == mesh_.vertex_count()) {
                entry.snapshot_vertex = inverse_vertex_map(result.old_to_new_vertex, after->vertex_count());
                report.old_to_new_vertex = std::move(result.old_to_new_vertex);
            }
            entry.snapshot = std::make_shared<const TetMesh>(std::move(mesh_));
            mesh_ = std::move(*after);
            min_dihedral_deg_ = min_dihedral_of(mesh_);
            report.topology = true;
        }
        details << result.pieces_before << " -> " << result.pieces_after << " pieces, " << result.vertices_merged
                << " vertices merged";
        report.result = without_arrays(std::move(result));
    }
}

}  // namespace waxwork
