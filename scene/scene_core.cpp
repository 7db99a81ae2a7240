#include "scene/scene_core.h"

#include "base/error.h"
#include "base/timing.h"
#include "io/surface_writer.h"
#include "io/volume_file.h"
#include "scene/surface_export.h"
#include "solver/solved_scene.h"
#include "solver/transport_validity.h"
#include "tetops/model_scale.h"

#include <array>
#include <chrono>

namespace waxwork {

namespace {

TetMesh with_tets(TetMesh mesh, const std::string& name) {
    if (mesh.tet_count() == 0) throw InvalidArgumentError(name + ": the volume has no tets");
    return mesh;
}

}  // namespace

SceneCore::SceneCore(TetMesh mesh, const Session& setup, LiveSceneOptions solver)
    : SceneCore(Document(with_tets(std::move(mesh), setup.name), setup.material), setup, std::move(solver)) {}

SceneCore::SceneCore(Document document, const Session& setup, LiveSceneOptions solver)
    : setup_(setup), document_(std::move(document)) {
    setup_.steps.clear();
    // A setup that names no scale (the editor's, a test's) gets the model's default, as an input would.
    if (!setup_.scale) setup_.scale = default_mm_per_unit(bounding_extent(document_.mesh().positions).norm());
    solver.mm_per_unit = *setup_.scale;
    solver.relative_tolerance = setup_.tolerance;
    solver.crease_angle_degrees = setup_.crease_angle_degrees;
    live_ = std::make_unique<LiveScene>(document_.mesh(), setup_.lighting, solver);
}

ChangeReport SceneCore::apply(const EditOperation& op) {
    ChangeReport report = document_.apply(op);
    live_->apply_change(document_.mesh(), report);
    return report;
}

std::optional<ChangeReport> SceneCore::undo() {
    std::optional<ChangeReport> report = document_.undo();
    if (report) live_->apply_change(document_.mesh(), *report);
    return report;
}

std::optional<ChangeReport> SceneCore::redo() {
    std::optional<ChangeReport> report = document_.redo();
    if (report) live_->apply_change(document_.mesh(), *report);
    return report;
}

ChangeReport SceneCore::preview_deform(const DeformOp& op, int iterations) {
    ChangeReport report = document_.preview_deform(op, iterations);
    live_->apply_change(document_.mesh(), report);
    return report;
}

ChangeReport SceneCore::commit_deform(const DeformOp& op) {
    ChangeReport report = document_.commit_deform(op);
    live_->apply_change(document_.mesh(), report);
    return report;
}

std::optional<ChangeReport> SceneCore::cancel_deform() {
    std::optional<ChangeReport> report = document_.cancel_deform();
    if (report) live_->apply_change(document_.mesh(), *report);
    return report;
}

void SceneCore::set_solver_options(const LiveSceneOptions& options) {
    const Lighting lighting = live_->lighting();
    live_.reset();  // it borrows the document's mesh: release before building the next one
    live_ = std::make_unique<LiveScene>(document_.mesh(), lighting, options);
    setup_.scale = options.mm_per_unit;
    setup_.tolerance = options.relative_tolerance;
    setup_.crease_angle_degrees = options.crease_angle_degrees;
}

void SceneCore::set_lighting(const Lighting& lighting) {
    live_->set_lighting(lighting);
    setup_.lighting = lighting;
}

void SceneCore::set_crease_angle(double degrees) {
    live_->set_crease_angle(degrees);
    setup_.crease_angle_degrees = degrees;
}

FrameReport SceneCore::step(const FrameBudget& budget) { return live_->step(budget); }

FrameReport SceneCore::converge() { return live_->converge(); }

void SceneCore::save_volume(const std::filesystem::path& path) const {
    write_volume(document_.mesh(), path, VolumeMetadata{setup_.scale});
}

bool SceneCore::export_surface(const std::filesystem::path& path, ShellGrouping grouping) {
    const bool colours = stores_vertex_colours(surface_format(path));
    std::optional<SolvedScene> solved;
    if (colours) {
        converge();
        solved = live_->solved_scene(false);
    }
    const SurfaceExport surface =
        surface_export(document_.mesh(), live_->connectivity(), grouping, solved ? &*solved : nullptr);
    write_surface(path, surface.shells, surface.colours);
    return colours;
}

void SceneCore::save_session(const std::filesystem::path& path, const Session& head,
                             const std::vector<SessionSnapshot>& snapshots, std::optional<double> exposure) const {
    // It replays to something: the image as the view shows it and the volume, named after the file.
    const std::string stem = path.stem().string();
    std::vector<AnchoredSteps> anchored;
    for (size_t k = 0; k < snapshots.size(); ++k) {
        const SessionSnapshot& s = snapshots[k];
        anchored.push_back({s.history, {CameraStep{s.camera}, LightStep{s.lighting},
                                        RenderStep{stem + "_snapshot_" + std::to_string(k + 1) + ".png", std::nullopt,
                                                   s.exposure}}});
    }
    std::vector<SessionStep> tail;
    if (!snapshots.empty()) tail = {CameraStep{head.camera}, LightStep{head.lighting}};
    tail.push_back(RenderStep{stem + ".png", std::nullopt, exposure});
    tail.push_back(SaveStep{stem + ".vtu"});
    write_session(path, record_session(head, document_, tail, anchored));
}

SceneTickResult SceneCore::tick(const SceneTickRequest& request, const std::function<void(const std::string&)>& stage) {
    const auto start = std::chrono::steady_clock::now();
    const auto set_stage = [&](const std::string& name) {
        if (stage) stage(name);
    };
    SceneTickResult r;
    for (const auto& [name, job] : request.jobs) {
        set_stage(name);
        try {
            r.messages.push_back(job(*this));
            r.geometry_changed = true;
        } catch (const std::exception& e) {
            r.errors.push_back(name + ": " + e.what());
        }
    }
    if (request.crease_angle) {
        set_stage("crease angle");
        set_crease_angle(*request.crease_angle);
        r.messages.push_back("Surface split where it folds by more than " + number_text(*request.crease_angle) +
                             " degrees");
        r.geometry_changed = true;  // the shading's vertices
    }
    if (request.lighting) set_lighting(*request.lighting);
    set_stage("solving");
    r.frame = live_->step(request.budget);
    r.converged = live_->converged();
    r.estimated_error = live_->estimated_error();
    const TetMesh& mesh = document_.mesh();
    if (request.first || r.geometry_changed) ++geometry_version_;
    if (request.lighting || r.frame.total_iterations() > 0) ++solution_version_;
    if (request.first || r.geometry_changed || request.lighting || r.frame.total_iterations() > 0 ||
        request.view_changed) {
        set_stage("radiance");
        // GPU backend in a context shared with the front end's (a window's): the image draws E from the
        // solver's device buffer, and the exposure is taken from a read-back of it, so E is not also
        // computed from phi on the CPU (at 100K tets that cost more than a device frame). Not with an
        // OSMesa context of the solver's own (when no shared context could be made): its buffers are
        // not the front end's.
        std::vector<std::array<float, 3>> device_e;
        std::shared_ptr<const GpuBuffer> device_buffer;
        if (live_->options().gl_context) device_buffer = live_->device_radiance(&device_e);
        const SolvedScene solved = live_->solved_scene(/*with_radiance=*/!device_buffer);
        r.input =
            make_render_input(mesh, solved, live_->lighting(), request.image, device_buffer ? &device_e : nullptr);
        if (request.view.mode != ViewMode::Radiance) {
            set_stage("view");
            r.view = view_cache_.get(mesh, live_->connectivity(), mesh.materials, solved, request.view,
                                     geometry_version_, solution_version_);
            apply_view(*r.view, *r.input);
        }
        r.input->device_radiance = device_buffer;
        if (request.need_bvh || r.geometry_changed) {
            r.bvh = std::make_shared<const TriangleBvh>(r.input->positions, r.input->triangles);
            // Each drawn (shading) vertex's piece, for picking pieces to move.
            std::vector<int32_t> vertex_piece(mesh.vertex_count(), 0);
            for (size_t t = 0; t < mesh.tet_count(); ++t)
                for (int32_t v : mesh.tets[t]) vertex_piece[v] = mesh.piece_ids[t];
            const ShadingSurface& shading = solved.shading;
            r.surface_piece.resize(shading.size());
            for (size_t d = 0; d < shading.size(); ++d)
                r.surface_piece[d] = vertex_piece[solved.surface.vertices[shading.surface_vertex[d]]];
        }
    }
    r.piece_transforms = mesh.piece_transforms;
    r.can_undo = document_.can_undo();
    r.can_redo = document_.can_redo();
    r.history = document_.history().size();
    r.tets = mesh.tet_count();
    r.vertices = mesh.vertex_count();
    r.min_dihedral = document_.min_dihedral_deg();
    if (request.first || r.geometry_changed) r.trust_warning = diffusion_trust_warning(mesh.materials);
    r.backend = live_->backend();
    r.solver_description = live_->solver_description();
    r.gpu_fallback_reason = live_->gpu_fallback_reason();
    r.method_fallback_reason = live_->method_fallback_reason();
    r.milliseconds = milliseconds_since(start);
    return r;
}

}  // namespace waxwork
