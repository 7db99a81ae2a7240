#include "scene/live_scene.h"

#include "base/error.h"
#include "base/timing.h"
#include "solver/conjugate_gradient.h"
#include "solver/radiance.h"
#include "solver/warm_start.h"

#include <algorithm>
#include <limits>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>

namespace waxwork {
namespace {

AssemblyOptions assembly_options(const LiveSceneOptions& options) {
    AssemblyOptions a;
    a.mm_per_unit = options.mm_per_unit;
    return a;
}

void check_materials(const TetMesh& mesh) {
    if (mesh.materials.size() != mesh.tet_count())
        throw InvalidArgumentError("live scene: the volume must store one material per tet (" +
                                   std::to_string(mesh.materials.size()) + " for " +
                                   std::to_string(mesh.tet_count()) + " tets)");
}

}  // namespace

LiveScene::LiveScene(const TetMesh& mesh, const Lighting& lighting, const LiveSceneOptions& options)
    : mesh_(&mesh), options_(options), lighting_(lighting) {
    if (!(options.mm_per_unit > 0) || !std::isfinite(options.mm_per_unit))
        throw InvalidArgumentError("live scene: mm_per_unit must be positive");
    if (!(options.relative_tolerance > 0) || !(options.relative_tolerance < 1))
        throw InvalidArgumentError("live scene: the relative tolerance must be in (0, 1)");
    validate(lighting_);  // the crease angle is checked by the first split_at_creases
    check_materials(mesh);
    solver_ = std::make_unique<LiveSolver>(
        LiveSolverOptions{options.method, options.backend, options.gl_context, options.clock, options.multigrid});
    SceneUpdate update;
    rebuild_all(nullptr, update);
}

void LiveScene::mark_unconverged() {
    converged_ = {false, false, false};
    solved_since_change_ = false;
}

void LiveScene::rebuild_surface(SceneUpdate& update, std::optional<std::span<const int32_t>> vertex_map) {
    BoundarySurface old_surface = std::move(surface_);
    surface_ = extract_boundary_surface(*mesh_, *connectivity_, mesh_->materials);
    // Moved vertices (a deformation, a piece moved) keep the triangles: the tree is refitted.
    if (!shadow_bvh_.empty() && surface_.triangles == old_surface.triangles)
        refit_shadow_bvh(shadow_bvh_, surface_);
    else
        shadow_bvh_ = build_shadow_bvh(surface_);
    shading_ = split_at_creases(surface_, options_.crease_angle_degrees);
    update.rebuilt_surface = true;
    if (transfer_ && vertex_map && lighting_.environment && transfer_->settings().order == lighting_.environment->sh_order &&
        transfer_->settings().shadows == lighting_.shadows) {
        // Only the vertices that can see what changed need sampling again, and those that stayed in
        // place wait for the next frames (carry_environment_transfer, refine_transfer).
        std::vector<int32_t> deferred;
        transfer_ = carry_environment_transfer(old_surface, *transfer_, surface_, shadow_bvh_, *vertex_map,
                                               &update.resampled_transfer, deferred_transfer_, &deferred);
        deferred_transfer_ = std::move(deferred);
        // The split copies (a cut's new rim has thousands) stand in with a few rays and are sampled
        // fully after the vertices.
        copy_transfer_.emplace(transfer_->settings(), shading_.split_copies.size());
        deferred_copies_.resize(shading_.split_copies.size());
        std::iota(deferred_copies_.begin(), deferred_copies_.end(), 0);
        update_split_copy_transfer(surface_, shading_, shadow_bvh_, deferred_copies_, *copy_transfer_,
                                   kInterimTransferSamples);
        update.deferred_transfer = deferred_transfer_.size() + deferred_copies_.size();
    } else {
        transfer_.reset();
        deferred_transfer_.clear();
        deferred_copies_.clear();
        if (lighting_.environment) update.resampled_transfer = surface_.positions.size();
    }
    relight(update);
}

void LiveScene::refresh_transfer() {
    if (!lighting_.environment) {
        transfer_.reset();
        copy_transfer_.reset();
        deferred_transfer_.clear();
        deferred_copies_.clear();
        return;
    }
    if (transfer_ && transfer_->settings().order == lighting_.environment->sh_order &&
        transfer_->settings().shadows == lighting_.shadows)
        return;
    deferred_transfer_.clear();
    deferred_copies_.clear();
    TransferSettings settings;
    settings.order = lighting_.environment->sh_order;
    settings.shadows = lighting_.shadows;
    transfer_ = compute_environment_transfer(surface_, shadow_bvh_, settings);
    copy_transfer_ = split_copy_transfer(surface_, shading_, shadow_bvh_, settings);
}

void LiveScene::refine_transfer(double milliseconds) {
    if (deferred_transfer_.empty() && deferred_copies_.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    // The surface's vertices first (most of the light), then the split copies.
    size_t done = 0;
    while (done < deferred_transfer_.size()) {
        const size_t count = std::min(kTransferRefineChunk, deferred_transfer_.size() - done);
        update_environment_transfer(surface_, shadow_bvh_, std::span(deferred_transfer_).subspan(done, count), *transfer_);
        done += count;
        if (milliseconds_since(start) >= milliseconds) break;
    }
    if (done > 0) {
        update_incident_light(surface_, shadow_bvh_, lighting_, std::span(deferred_transfer_).first(done), surface_q_,
                              &*transfer_);
        deferred_transfer_.erase(deferred_transfer_.begin(), deferred_transfer_.begin() + static_cast<std::ptrdiff_t>(done));
    }
    size_t copies_done = 0;
    while (deferred_transfer_.empty() && copies_done < deferred_copies_.size() &&
           ((copies_done == 0 && done == 0) || milliseconds_since(start) < milliseconds)) {
        const size_t count = std::min(kTransferRefineChunk, deferred_copies_.size() - copies_done);
        update_split_copy_transfer(surface_, shading_, shadow_bvh_, std::span(deferred_copies_).subspan(copies_done, count),
                                   *copy_transfer_);
        copies_done += count;
    }
    deferred_copies_.erase(deferred_copies_.begin(), deferred_copies_.begin() + static_cast<std::ptrdiff_t>(copies_done));
    light_shading();
    refresh_right_hand_sides();
}

void LiveScene::relight(SceneUpdate& update) {
    refresh_transfer();
    surface_q_ = incident_light(surface_, shadow_bvh_, lighting_, &surface_visibility_, transfer_ ? &*transfer_ : nullptr);
    light_shading();
    update.recomputed_light = true;
    refresh_right_hand_sides();
}

void LiveScene::light_shading() {
    shading_light_ = shading_light(surface_, shading_, shadow_bvh_, lighting_, surface_q_, surface_visibility_,
                                   copy_transfer_ ? &*copy_transfer_ : nullptr);
    const std::vector<Rgb> surface_source_q = source_light(surface_, shading_, shading_light_.q);
    corners_ = corner_light(surface_, shading_, shading_light_.q, surface_source_q);
    q_ = to_volume_vertices(surface_, surface_source_q, matrix_.size());
}

SceneUpdate LiveScene::set_crease_angle(double degrees) {
    const std::lock_guard lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    SceneUpdate update;
    if (degrees == options_.crease_angle_degrees) return update;
    // Split first: a bad angle throws before anything changes.
    shading_ = split_at_creases(surface_, degrees);
    options_.crease_angle_degrees = degrees;
    if (transfer_) copy_transfer_ = split_copy_transfer(surface_, shading_, shadow_bvh_, transfer_->settings());
    deferred_copies_.clear();
    light_shading();
    update.recomputed_light = true;
    refresh_right_hand_sides();
    update.milliseconds = milliseconds_since(start);
    return update;
}

void LiveScene::refresh_right_hand_sides() {
    const size_t n = matrix_.size();
    for (int c = 0; c < 3; ++c) {
        b_[c].resize(n);
        diffusion_right_hand_side(matrix_, q_, c, b_[c]);
        add_corner_light(matrix_, corners_, c, b_[c]);
    }
    solver_->right_hand_sides_changed();
    mark_unconverged();
}

void LiveScene::rebuild_all(std::shared_ptr<const TetConnectivity> connectivity, SceneUpdate& update,
                            std::span<const int32_t> new_of_old_vertex) {
    const std::optional<std::span<const int32_t>> vertex_map =
        new_of_old_vertex.empty() ? std::nullopt : std::optional(new_of_old_vertex);
    if (!connectivity) {
        connectivity = std::make_shared<const TetConnectivity>(build_connectivity(*mesh_));
        update.rebuilt_connectivity = true;
    }
    connectivity_ = std::move(connectivity);
    matrix_ = assemble_diffusion_matrix(*mesh_, *connectivity_, mesh_->materials, assembly_options(options_));
    update.reassembled_matrix = true;
    rebuild_surface(update, vertex_map);
    // Also drops the smallest-eigenvalue hints of the old matrix: a stale hint could be too large and
    // make the error estimate optimistic.
    solver_->matrix_rebuilt(*mesh_, matrix_, new_of_old_vertex);
    for (auto& phi : phi_) phi.resize(matrix_.size(), 0.0);
}

SceneUpdate LiveScene::apply_change(const TetMesh& mesh, const ChangeReport& change) {
    const std::lock_guard lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    SceneUpdate update;
    mesh_ = &mesh;
    check_materials(mesh);
    if (change.topology) {
        // Carry phi over where the change says where vertices went (a cut, a fracture, a weld, their
        // undo); else start cold. Origins (exact cuts, fractures) also place the vertices made on
        // edges and a fracture's crack copies (solver/warm_start.h).
        const size_t n_old = phi_[0].size();
        const bool mapped = !change.old_to_new_vertex.empty() && change.old_to_new_vertex.size() == n_old;
        const bool from_origins = change.vertex_origins.size() == mesh.vertex_count() && !mesh.positions.empty();
        CarriedValues carried;
        if (from_origins) {
            carried = carry_through_origins(phi_, change.vertex_origins);
        } else if (mapped) {
            carried = carry_through_vertex_map(phi_, change.old_to_new_vertex, mesh.vertex_count());
        } else {
            for (auto& channel : carried.values) channel.assign(mesh.vertex_count(), 0.0);
            carried.known.assign(mesh.vertex_count(), 0);
        }
        phi_ = std::move(carried.values);
        update.warm_start = mapped || from_origins;
        const bool reuse = change.connectivity && change.connectivity->vertex_tets.row_count() == mesh.vertex_count() &&
                           change.connectivity->tet_neighbors.size() == mesh.tet_count();
        rebuild_all(reuse ? change.connectivity : nullptr, update,
                    mapped ? std::span<const int32_t>(change.old_to_new_vertex) : std::span<const int32_t>());
        // Vertices the change gave no value (undoing a cut or a weld restores some) start from their
        // neighbours' values instead of zero (solver/warm_start.h).
        if (update.warm_start) extend_to_unknown_vertices(matrix_, carried.known, phi_);
    } else if (change.positions) {
        // Same tets, moved vertices (a deformation, a relaxation): the geometry of the tets around the
        // moved vertices changes, so exactly their rows are rewritten on the kept pattern, and the
        // solver's hierarchy keeps its graph and updates its values (as for painted materials).
        if (change.moved_vertices.empty()) {
            matrix_ = assemble_diffusion_matrix(mesh, *connectivity_, mesh.materials, assembly_options(options_));
            update.reassembled_matrix = true;
            std::vector<int32_t> same_vertices(mesh.vertex_count());
            std::iota(same_vertices.begin(), same_vertices.end(), 0);
            solver_->matrix_rebuilt(mesh, matrix_, same_vertices);
        } else {
            update.updated_rows = update_diffusion_geometry(matrix_, mesh, *connectivity_, change.moved_vertices);
            solver_->rows_changed(update.updated_rows);
        }
        // The surface keeps its numbering (the empty vertex map): the environment transfer keeps the
        // vectors of vertices that barely turned for the next frames and samples the rest now
        // (carry_environment_transfer).
        rebuild_surface(update, std::span<const int32_t>());
    } else {
        bool eta_changed = false;
        if (change.all_materials) {
            assemble_diffusion_values(matrix_, *connectivity_, mesh.materials);
            solver_->values_changed();
            update.recomputed_values = true;
            eta_changed = true;
        } else if (!change.changed_material_tets.empty()) {
            update.updated_rows = update_diffusion_matrix(matrix_, mesh, *connectivity_, mesh.materials,
                                                          change.changed_material_tets);
            solver_->rows_changed(update.updated_rows);
            // q depends on eta through the Fresnel transmittance: only a changed tet with a boundary
            // face can change a boundary vertex's eta.
            for (const int32_t t : change.changed_material_tets) {
                const auto& n = connectivity_->tet_neighbors[t];
                if (std::find(n.begin(), n.end(), -1) != n.end()) {
                    eta_changed = true;
                    break;
                }
            }
        }
        if (eta_changed) {
            const std::vector<double> eta = boundary_vertex_eta(mesh, *connectivity_, mesh.materials);
            std::vector<int32_t> changed;
            for (size_t s = 0; s < surface_.vertices.size(); ++s) {
                // Blending equal etas ((1 - w) eta + w eta) can round by an ulp: that changes q by
                // 1e-16 relative, not worth recomputing.
                if (std::abs(surface_.eta[s] - eta[surface_.vertices[s]]) > 1e-12) changed.push_back(static_cast<int32_t>(s));
                surface_.eta[s] = eta[surface_.vertices[s]];
            }
            eta_changed = !changed.empty();
            if (eta_changed && !change.piece_transforms) {
                // Only those vertices' Fresnel transmittance changed: recompute q there (shadow rays
                // included), not on the whole surface.
                if (transfer_) {
                    update_environment_transfer(surface_, shadow_bvh_, changed, *transfer_);
                    // The split copies of those vertices integrate with the new eta too.
                    std::vector<uint8_t> is_changed(surface_.positions.size(), 0);
                    for (const int32_t v : changed) is_changed[v] = 1;
                    std::vector<int32_t> copies;
                    for (size_t i = 0; i < shading_.split_copies.size(); ++i)
                        if (is_changed[shading_.surface_vertex[shading_.split_copies[i]]]) copies.push_back(static_cast<int32_t>(i));
                    update_split_copy_transfer(surface_, shading_, shadow_bvh_, copies, *copy_transfer_);
                }
                update_incident_light(surface_, shadow_bvh_, lighting_, changed, surface_q_, transfer_ ? &*transfer_ : nullptr);
                light_shading();
                update.recomputed_light = true;
            }
        }
        if (change.piece_transforms) {
            // Rigid motions leave the matrix (built on rest positions) unchanged but move the pieces'
            // shadows onto each other.
            rebuild_surface(update, std::span<const int32_t>());
        } else if (eta_changed || update.recomputed_values) {
            refresh_right_hand_sides();  // the source operator (A, F_dr) follows the materials
        } else if (!update.updated_rows.empty()) {
            // q is unchanged and only the rewritten rows of the source operator can differ: b changes
            // in those rows only (b = source * q, Eq. 12, plus the corners' share, whose coefficients
            // changed only in those rows too). Cheaper than a full product per channel.
            for (const int32_t i : update.updated_rows) {
                std::array<double, 3> sum{};
                if (matrix_.vertex_face_offsets[i] != matrix_.vertex_face_offsets[i + 1])
                    for (int32_t k = matrix_.offsets[i]; k < matrix_.offsets[i + 1]; ++k)
                        for (int c = 0; c < 3; ++c) sum[c] += matrix_.source[k] * q_[matrix_.columns[k]][c];
                for (int c = 0; c < 3; ++c) b_[c][i] = sum[c];
            }
            if (!corners_.empty()) {
                std::vector<uint8_t> rows(matrix_.size(), 0);
                for (const int32_t i : update.updated_rows) rows[i] = 1;
                for (int c = 0; c < 3; ++c) add_corner_light(matrix_, corners_, c, b_[c], rows);
            }
            solver_->right_hand_sides_changed();
        }
    }
    mark_unconverged();
    update.milliseconds = milliseconds_since(start);
    return update;
}

SceneUpdate LiveScene::set_lighting(const Lighting& lighting) {
    validate(lighting);
    const std::lock_guard lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    lighting_ = lighting;
    SceneUpdate update;
    relight(update);
    update.milliseconds = milliseconds_since(start);
    return update;
}

FrameReport LiveScene::iterate(int iteration_budget, const FrameBudget* time_budget) {
    const auto start = std::chrono::steady_clock::now();
    refine_transfer(kTransferRefineMilliseconds);
    FrameReport report;
    const size_t n = matrix_.size();
    std::array<bool, 3> skip{};
    for (int c = 0; c < 3; ++c) skip[c] = converged_[c] || n == 0;
    const double tolerance = options_.relative_tolerance;
    const auto channels = time_budget ? solver_->iterate(matrix_, b_, phi_, *time_budget, tolerance, skip)
                                      : solver_->iterate(matrix_, b_, phi_, iteration_budget, tolerance, skip);
    for (int c = 0; c < 3; ++c) {
        if (skip[c]) {
            converged_[c] = true;
            report.estimated_relative_error[c] = n == 0 ? 0 : error_[c];
            continue;
        }
        report.iterations[c] = channels[c].iterations;
        error_[c] = channels[c].estimated_relative_error;
        converged_[c] = channels[c].converged;
        report.estimated_relative_error[c] = error_[c];
    }
    report.converged = converged_[0] && converged_[1] && converged_[2] && deferred_transfer_.empty() &&
                       deferred_copies_.empty();
    solved_since_change_ = true;
    report.milliseconds = milliseconds_since(start);
    return report;
}

FrameReport LiveScene::step(int iteration_budget) {
    if (iteration_budget < 0) throw InvalidArgumentError("live scene: the iteration budget must be >= 0");
    const std::lock_guard lock(mutex_);
    return iterate(iteration_budget);
}

FrameReport LiveScene::step(const FrameBudget& budget) {
    validate(budget);
    const std::lock_guard lock(mutex_);
    return iterate(budget.max_iterations, &budget);
}

FrameReport LiveScene::step_for(double milliseconds, int chunk_iterations) {
    if (!(milliseconds >= 0) || chunk_iterations < 1)
        throw InvalidArgumentError("live scene: the time budget must be >= 0 and the chunk >= 1 iteration");
    const std::lock_guard lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    FrameReport total;
    do {
        const FrameReport chunk = iterate(chunk_iterations);
        for (int c = 0; c < 3; ++c) total.iterations[c] += chunk.iterations[c];
        total.estimated_relative_error = chunk.estimated_relative_error;
        total.converged = chunk.converged;
    } while (!total.converged && milliseconds_since(start) < milliseconds);
    total.milliseconds = milliseconds_since(start);
    return total;
}

FrameReport LiveScene::converge(int max_iterations) {
    const std::lock_guard lock(mutex_);
    // A channel that stopped inside its budget met its precision's floor (conjugate_gradient.h):
    // more iterations would not help, another precision might. A multigrid budget counts V-cycles.
    refine_transfer(std::numeric_limits<double>::infinity());
    const int budget = options_.method == LiveMethod::MultigridCg ? std::max(1, max_iterations / 4) : max_iterations;
    const auto at_floor = [&](const FrameReport& report) {
        for (int c = 0; c < 3; ++c)
            if (!converged_[c] && report.iterations[c] < budget) return true;
        return false;
    };
    FrameReport report = iterate(max_iterations);
    std::optional<FrameReport> on_cpu;  // the CPU's run after a hand-over from the GPU
    if (!report.converged && at_floor(report) && solver_->backend() == LiveBackend::Gpu) {
        // The GPU solves in float; a tolerance below its floor on this volume (slivers raise it) is
        // reached in double on the CPU, from the GPU's phi, and the switch is reported like a driver's.
        std::ostringstream reason;
        reason << "GPU solver: float stopped at an estimated relative error of " << report.max_error()
               << ", above the tolerance " << options_.relative_tolerance
               << " (its precision floor on this volume); the CPU solves in double from here";
        solver_->fall_back_to_cpu(reason.str());
        on_cpu = iterate(max_iterations);
        for (int c = 0; c < 3; ++c) {
            report.iterations[c] += on_cpu->iterations[c];
            report.estimated_relative_error[c] = on_cpu->estimated_relative_error[c];
        }
        report.converged = on_cpu->converged;
        report.milliseconds += on_cpu->milliseconds;
    }
    if (!report.converged) {
        std::ostringstream msg;
        msg << "live scene: the diffusion solve did not reach relative error " << options_.relative_tolerance;
        // Against the budget of the last backend's own run (the totals span two runs after a hand-over).
        if (at_floor(on_cpu ? *on_cpu : report))
            msg << ": it stopped at an estimated " << report.max_error() << ", the precision floor of "
                << solver_->description() << " on this volume";
        else
            msg << " in " << max_iterations << " iterations (estimated " << report.max_error() << ")";
        throw AlgorithmError(msg.str());
    }
    return report;
}

bool LiveScene::converged() const {
    const std::lock_guard lock(mutex_);
    return converged_[0] && converged_[1] && converged_[2] && deferred_transfer_.empty() && deferred_copies_.empty();
}

size_t LiveScene::deferred_transfer() const {
    const std::lock_guard lock(mutex_);
    return deferred_transfer_.size() + deferred_copies_.size();
}

std::optional<double> LiveScene::estimated_error() const {
    const std::lock_guard lock(mutex_);
    if (!solved_since_change_) return std::nullopt;
    return std::max({error_[0], error_[1], error_[2]});
}

Lighting LiveScene::lighting() const {
    const std::lock_guard lock(mutex_);
    return lighting_;
}

std::vector<std::array<double, 3>> LiveScene::phi() const {
    const std::lock_guard lock(mutex_);
    std::vector<std::array<double, 3>> phi(matrix_.size());
    for (size_t v = 0; v < phi.size(); ++v)
        for (int c = 0; c < 3; ++c) phi[v][c] = phi_[c][v];
    return phi;
}

LiveBackend LiveScene::backend() const {
    const std::lock_guard lock(mutex_);
    return solver_->backend();
}

std::string LiveScene::gpu_fallback_reason() const {
    const std::lock_guard lock(mutex_);
    return solver_->gpu_fallback_reason();
}

std::string LiveScene::method_fallback_reason() const {
    const std::lock_guard lock(mutex_);
    return solver_->method_fallback_reason();
}

std::string LiveScene::solver_description() const {
    const std::lock_guard lock(mutex_);
    return solver_->description();
}

std::vector<std::array<int64_t, 2>> LiveScene::multires_levels() const {
    const std::lock_guard lock(mutex_);
    std::vector<std::array<int64_t, 2>> levels;
    if (const MultiresHierarchy* hierarchy = solver_->multires_hierarchy())
        for (const HierarchyLevel& level : hierarchy->levels)
            levels.push_back({static_cast<int64_t>(level.size()), level.changed_vertices});
    return levels;
}

int64_t LiveScene::multigrid_copied_rows() const {
    const std::lock_guard lock(mutex_);
    const MultigridPreconditioner* preconditioner = solver_->multigrid_preconditioner();
    if (!preconditioner) return -1;
    int64_t rows = 0;
    for (size_t l = 0; l < preconditioner->level_count(); ++l)
        rows += static_cast<int64_t>(preconditioner->copied_operator_rows(l));
    return rows;
}

std::shared_ptr<const GpuBuffer> LiveScene::device_radiance(std::vector<std::array<float, 3>>* host_copy) {
    const std::lock_guard lock(mutex_);
    return solver_->radiance_on_device(surface_, shading_, shading_light_.q, host_copy);
}

std::vector<std::array<float, 3>> LiveScene::radiance_factors() const {
    const std::vector<std::array<double, 3>> phi = this->phi();
    const std::lock_guard lock(mutex_);
    return shading_radiance_factors(surface_, shading_, phi, shading_light_.q);
}

SolvedScene LiveScene::solved_scene(bool with_radiance) const {
    SolvedScene scene;
    scene.diffusion.phi = phi();
    const std::lock_guard lock(mutex_);
    scene.surface = surface_;
    scene.shading = shading_;
    scene.shading_light = shading_light_;
    scene.q = q_;
    for (int c = 0; c < 3; ++c) scene.diffusion.estimated_relative_error[c] = error_[c];
    if (with_radiance)
        scene.radiance_factor =
            shading_radiance_factors(scene.surface, scene.shading, scene.diffusion.phi, scene.shading_light.q);
    return scene;
}

}  // namespace waxwork
