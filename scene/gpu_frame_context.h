// The OpenGL context the GPU frame solvers of one LiveSolver share: the one LiveSolverOptions gives
// (the editor's hidden window sharing the main window's objects, or a borrowed OSMesa context), or an
// OSMesa/EGL context opened at the first GPU frame that needs one. One per LiveSolver, so that a GPU
// method replacing another (Jacobi CG after a multigrid V-cycle that cannot be built) solves in the
// same context. The context is made current around every GPU call: the editor runs each frame on a
// new worker thread.
#pragma once

#include "gl/gpu_compute.h"
#include "gl/shared_context.h"
#include "scene/frame_solver.h"

#include <memory>
#include <string>

namespace waxwork {

class GpuFrameContext {
public:
    explicit GpuFrameContext(std::shared_ptr<SolverGlContext> context) : context_(std::move(context)) {}

    // Null until given or opened.
    SolverGlContext* get() const { return context_.get(); }
    // The context, opened now if there is none yet (throws as open_headless_solver_context).
    SolverGlContext& open();
    // Reads the renderer's name (GL_RENDERER) after a device solver was made on `gl`.
    void note_renderer(const GlApi& gl);
    // `text` followed by the renderer's name, once a device solver was made: "GPU Jacobi CG (float)
    // (llvmpipe ...)".
    std::string with_renderer(std::string text) const;

    // Makes the device copy `device` when there is none, on `gl` (this context, current): checks for
    // compute shaders (GpuError without them), sets its `solver` to what `make_solver` returns and
    // notes the renderer. Returns whether it made one (a new copy: the caller's pending changes restart).
    template <class Device, class MakeSolver>
    bool make_device(std::unique_ptr<Device>& device, const GlApi& gl, MakeSolver&& make_solver) {
        if (device) return false;
        require_compute_support(gl);
        auto made = std::make_unique<Device>();
        made->solver = make_solver();
        device = std::move(made);
        note_renderer(gl);
        return true;
    }

    // Frees `device` (an object holding buffers of this context) with the context current. Throws when
    // the context cannot be made current; `device` is then kept.
    template <class Device>
    void free_device(std::unique_ptr<Device>& device) {
        if (!device) return;
        if (context_) {
            const CurrentContext current(*context_);
            device.reset();
        } else {
            device.reset();
        }
    }
    // The same for a new matrix (FrameSolver::matrix_rebuilt: a new pattern, made again at the next
    // frame); a failure is the device's, reported as GpuError "GPU solver: ...".
    template <class Device>
    void free_device_for_new_matrix(std::unique_ptr<Device>& device) {
        try {
            free_device(device);
        } catch (const std::exception& e) {
            throw GpuError(std::string("GPU solver: ") + e.what());
        }
    }
    // The same where nothing could act on a failure (a destructor, a fallback): a context that cannot
    // be made current any more leaks the device rather than crash.
    template <class Device>
    void free_device_or_leak(std::unique_ptr<Device>& device) noexcept {
        try {
            free_device(device);
        } catch (...) {
            (void)device.release();
        }
    }

private:
    std::shared_ptr<SolverGlContext> context_;
    std::string renderer_;
};

// The result of a GPU frame with nothing to solve (an empty matrix, or every channel skipped): no
// iterations, no device work.
std::array<LiveSolverChannel, 3> idle_gpu_frame(size_t n, const std::array<bool, 3>& skip);

}  // namespace waxwork
