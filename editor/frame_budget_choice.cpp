// The solver panel's frame budget: each tick's solver step is limited either to a
// number of iterations or to a time in milliseconds (solver/frame_budget.h). A time budget keeps the
// frame rate steady whatever the mesh size, method and backend; an iteration budget keeps frames
// reproducible. The budget covers the solver step only: a tick's edits and radiance come on top.
#include "editor/editor_app.h"

#include <imgui.h>

namespace waxwork {

void EditorApp::draw_frame_budget_choice() {
    int mode = frame_budget_in_ms_ ? 1 : 0;
    if (ImGui::Combo("frame budget", &mode, "iterations / frame\0ms / frame\0")) frame_budget_in_ms_ = mode == 1;
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("How much solving each frame does: a count of iterations (reproducible frames)\n"
                          "or a time (a steady frame rate on any mesh, method and backend).");
    if (frame_budget_in_ms_) {
        ImGui::SliderFloat("ms / frame", &frame_ms_, 1.0f, 100.0f, "%.0f ms", ImGuiSliderFlags_Logarithmic);
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Solver time per frame. CPU: CG (each channel its share) or V-cycles stop at the\n"
                              "deadline; an iteration that started finishes, at least one runs. GPU: the\n"
                              "iterations that fit, predicted from the previous frames' times.");
    } else {
        ImGui::SliderInt("iterations / frame", &frame_iterations_, 1, 200);
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Jacobi CG: CG iterations per channel and frame.\n"
                              "Multigrid CG: one V-cycle (all three channels) per 4, at least one.");
    }
}

FrameBudget EditorApp::frame_budget() const {
    return frame_budget_in_ms_ ? FrameBudget::milliseconds(frame_ms_) : FrameBudget::iterations(frame_iterations_);
}

void EditorApp::adopt_frame_budget(const Session& session) {
    // As stored, even outside the sliders' ranges (a slider clamps only what the user drags).
    frame_iterations_ = session.frame_iterations;
    if (options_.frame_ms) return;  // the command line's --frame-ms wins
    frame_budget_in_ms_ = session.frame_ms.has_value();
    if (session.frame_ms) frame_ms_ = static_cast<float>(*session.frame_ms);
}

}  // namespace waxwork
