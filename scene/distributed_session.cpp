#include "scene/distributed_session.h"

#include "base/error.h"
#include "base/timing.h"
#include "io/image_io.h"
#include "io/output_folder.h"
#include "io/volume_file.h"
#include "render/distributed_render.h"
#include "scene/document.h"
#include "solver/petsc_runtime.h"

#include <chrono>
#include <optional>
#include <string>
#include <system_error>
#include <variant>

namespace waxwork {
namespace {

const char* step_name(const SessionStep& step) {
    if (std::holds_alternative<RenderStep>(step)) return "render";
    if (std::holds_alternative<SaveStep>(step)) return "save";
    if (std::holds_alternative<LightStep>(step)) return "light";
    if (std::holds_alternative<CameraStep>(step)) return "camera";
    return "edit";
}

void check_steps(const Session& session) {
    for (size_t i = 0; i < session.steps.size(); ++i) {
        const SessionStep& step = session.steps[i];
        const auto* render = std::get_if<RenderStep>(&step);
        const bool supported = (render && !render->frames) || std::holds_alternative<SaveStep>(step) ||
                               std::holds_alternative<LightStep>(step) || std::holds_alternative<CameraStep>(step);
        if (!supported)
            throw InvalidArgumentError(session.name + ": step " + std::to_string(i) +
                                       ": --engine petsc replays converged renders, saves, lights and cameras only "
                                       "(edits, undo, redo and live frames run with --engine cpu)");
    }
}

}  // namespace

DistributedSessionResult run_session_distributed(const Session& session, const std::filesystem::path& output_directory,
                                                 PetscPeer preconditioner) {
    DistributedSessionResult result;
    const PetscProcesses processes = petsc_processes();
    result.rank = processes.rank;
    result.processes = processes.size;
    const bool root = processes.rank == 0;

    std::optional<Document> document;
    double mm_per_unit = 1;
    agreed_step([&] {
        check_steps(session);
        if (root) {
            std::error_code error;
            std::filesystem::create_directories(output_directory, error);
            if (error) throw FileError(output_directory.string(), "cannot create the directory: " + error.message());
        }
        const auto start = std::chrono::steady_clock::now();
        SessionVolume input = load_session_input(session);
        mm_per_unit = input.scale.mm_per_unit;
        document.emplace(std::move(input.mesh), session.material);
        result.load_ms = milliseconds_since(start);
    });
    const TetMesh& mesh = document->mesh();
    result.input_tets = mesh.tet_count();
    // A surface is meshed by every process: they must agree on the volume before splitting its rows.
    const std::vector<int64_t> tets = gather_from_all(static_cast<int64_t>(mesh.tet_count()));
    const std::vector<int64_t> vertices = gather_from_all(static_cast<int64_t>(mesh.vertex_count()));
    agreed_step([&] {
        for (size_t p = 1; p < tets.size(); ++p)
            if (tets[p] != tets[0] || vertices[p] != vertices[0])
                throw AlgorithmError(session.name + ": the processes meshed the input differently (" +
                                     std::to_string(tets[0]) + " and " + std::to_string(tets[p]) +
                                     " tets): mesh it once with `waxwork mesh` and start the session from the volume");
    });

    Lighting lighting = session.lighting;
    ImageSettings image;
    image.width = session.width;
    image.height = session.height;
    image.camera = session.camera;
    for (size_t i = 0; i < session.steps.size(); ++i) {
        const SessionStep& step = session.steps[i];
        const std::string context = session.name + ": step " + std::to_string(i) + " (" + step_name(step) + ")";
        const auto start = std::chrono::steady_clock::now();
        StepMetrics metrics;
        metrics.name = step_name(step);
        if (const auto* render = std::get_if<RenderStep>(&step)) {
            VolumeRenderSettings settings;
            settings.lighting = lighting;
            settings.diffusion.mm_per_unit = mm_per_unit;
            settings.diffusion.relative_tolerance = session.tolerance;
            settings.crease_angle_degrees = session.crease_angle_degrees;
            settings.image = image;
            if (render->exposure) settings.image.exposure = static_cast<float>(*render->exposure);
            // Errors name the session and the step (the name render_volume_distributed puts before them).
            const DistributedRender drawn = render_volume_distributed(mesh, context, settings, preconditioner);
            result.edges = drawn.edges;
            result.edge_cut = drawn.edge_cut;
            for (const int n : drawn.solve.iterations) metrics.solver_iterations += n;
            agreed_step([&] {
                if (!root) return;
                const std::filesystem::path path = contained_output_path(output_directory, render->file);
                write_png(drawn.render.image, path);
                result.written.push_back(path);
            });
        } else if (const auto* save = std::get_if<SaveStep>(&step)) {
            agreed_step([&] {
                if (!root) return;
                const std::filesystem::path path = contained_output_path(output_directory, save->file);
                write_volume(mesh, path, VolumeMetadata{mm_per_unit});
                result.written.push_back(path);
            });
        } else if (const auto* light = std::get_if<LightStep>(&step)) {
            lighting = light->lighting;
        } else {
            image.camera = std::get<CameraStep>(step).camera;
        }
        metrics.milliseconds = milliseconds_since(start);
        metrics.tets = mesh.tet_count();
        metrics.vertices = mesh.vertex_count();
        result.steps.push_back(metrics);
    }
    return result;
}

}  // namespace waxwork
