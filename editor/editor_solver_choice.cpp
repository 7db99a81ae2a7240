// The solver panel's method and backend choice: switching rebuilds the live scene with the
// new LiveSolver (live_solver.h); the GPU backend runs in a hidden window's context shared with this
// window's (window_gl_context.h). A context or shader that fails shows its reason here and the scene
// keeps solving on the CPU.
#include "editor/editor_app.h"
#include "editor/window_gl_context.h"

#include <imgui.h>

namespace waxwork {

void EditorApp::choose_solver(LiveMethod method, LiveBackend backend) {
    live_options_.method = method;
    live_options_.backend = backend;
    if (backend == LiveBackend::Gpu && !solver_context_ && solver_context_error_.empty()) {
        solver_context_ = open_shared_window_context(window_, solver_context_error_);
    }
    // Without a shared context the solver opens an OSMesa one of its own (still a GPU-path solve, on
    // llvmpipe), or falls back to the CPU with the reason.
    live_options_.gl_context = backend == LiveBackend::Gpu ? solver_context_ : nullptr;
}

void EditorApp::draw_solver_choice() {
    int method = live_options_.method == LiveMethod::MultigridCg ? 1 : live_options_.method == LiveMethod::Multires ? 2 : 0;
    int backend = live_options_.backend == LiveBackend::Gpu ? 1 : 0;
    bool changed = ImGui::Combo("method", &method, "Jacobi CG\0Multigrid CG (rgb per V-cycle)\0Multires (paper Sec. 4)\0");
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Jacobi-preconditioned CG per channel (double on the CPU, float on the GPU).\n"
                          "Multigrid CG, three channels per V-cycle: CG preconditioned by a V-cycle on the\n"
                          "multires hierarchy, warm across frames, one V-cycle per 4 iterations of the budget\n"
                          "(CPU, or the device: the same V-cycle in float there).\n"
                          "Multires: the paper's scheme, BiCGSTAB coarse to fine after a rebuild, then a warm\n"
                          "level-0 CG per frame; painting updates only the changed rows of every level. Runs on\n"
                          "the CPU or on the device.");
    changed |= ImGui::Combo("backend", &backend, "CPU\0GPU (OpenGL compute)\0");
    if (changed) {
        choose_solver(method == 1   ? LiveMethod::MultigridCg
                      : method == 2 ? LiveMethod::Multires
                                    : LiveMethod::JacobiCg,
                      backend == 1 ? LiveBackend::Gpu : LiveBackend::Cpu);
        rebuild_live_scene();
    }
    const Scene& s = *scene_;
    if (s.core && !s.solver_description.empty()) ImGui::TextDisabled("solving with %s", s.solver_description.c_str());
    std::string reason = s.gpu_fallback_reason;
    if (reason.empty() && live_options_.backend == LiveBackend::Gpu) reason = solver_context_error_;
    if (!reason.empty() && live_options_.backend == LiveBackend::Gpu) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.6f, 0.3f, 1.0f));
        ImGui::TextWrapped("GPU unavailable, solving on the CPU: %s", reason.c_str());
        ImGui::PopStyleColor();
    }
    if (!s.method_fallback_reason.empty()) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.6f, 0.3f, 1.0f));
        ImGui::TextWrapped("%s", s.method_fallback_reason.c_str());
        ImGui::PopStyleColor();
    }
}

}  // namespace waxwork
