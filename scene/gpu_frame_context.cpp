#include "scene/gpu_frame_context.h"

namespace waxwork {

SolverGlContext& GpuFrameContext::open() {
    if (!context_) context_ = open_headless_solver_context();
    return *context_;
}

void GpuFrameContext::note_renderer(const GlApi& gl) {
    const GLubyte* renderer = gl.GetString(GL_RENDERER);
    renderer_ = renderer ? reinterpret_cast<const char*>(renderer) : "";
}

std::string GpuFrameContext::with_renderer(std::string text) const {
    if (!renderer_.empty()) text += " (" + renderer_ + ")";
    return text;
}

std::array<LiveSolverChannel, 3> idle_gpu_frame(size_t n, const std::array<bool, 3>& skip) {
    std::array<LiveSolverChannel, 3> out;
    for (int c = 0; c < 3; ++c) out[c] = {0, skip[c] ? 0.0 : 1.0, skip[c] || n == 0};
    return out;
}

}  // namespace waxwork
