// GPU Jacobi CG as a frame solver: solver/gpu/gpu_conjugate_gradient.h (float, OpenGL 4.3 compute
// shaders). The matrix, the right-hand sides and phi stay on the device between frames; painting
// uploads only the rewritten rows (GpuDiffusionSolver::update_rows). phi is read back after each frame
// so that the host copy (LiveScene::phi, saves, the CPU radiance) stays valid. The device queue cannot
// stop part-way: a time budget reaches it as an iteration count (FrameSolver::checks_deadline).
#pragma once

#include "scene/device_radiance.h"
#include "scene/frame_solver.h"
#include "scene/gpu_frame_context.h"
#include "scene/pending_changes.h"
#include "solver/gpu/gpu_conjugate_gradient.h"

#include <array>
#include <memory>
#include <vector>

namespace waxwork {

class GpuJacobiFrameSolver : public FrameSolver {
public:
    // `context` outlives this object.
    explicit GpuJacobiFrameSolver(GpuFrameContext& context) : context_(context) {}
    ~GpuJacobiFrameSolver() override { context_.free_device_or_leak(device_); }
    GpuJacobiFrameSolver(const GpuJacobiFrameSolver&) = delete;
    GpuJacobiFrameSolver& operator=(const GpuJacobiFrameSolver&) = delete;

    // Frees the device copy (made again at the next frame); throws GpuError when it cannot be freed.
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override;
    void values_changed() override { pending_.values_changed(); }
    void rows_changed(std::span<const int32_t> rows) override { pending_.rows_changed(rows); }
    void right_hand_sides_changed() override { pending_.right_hand_sides = true; }
    void solution_changed() override { pending_.solution = true; }

    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;
    bool checks_deadline() const override { return false; }
    bool next_frame_measures_iterations() const override { return device_ && !pending_.all_values; }

    std::shared_ptr<const GpuBuffer> radiance_on_device(const BoundarySurface& surface, const ShadingSurface& shading,
                                                        const std::vector<std::array<double, 3>>& shading_q,
                                                        std::vector<std::array<float, 3>>* host_copy) override {
        return device_copy_radiance(context_, device_.get(), surface, shading, shading_q, host_copy);
    }
    std::unique_ptr<FrameSolver> cpu_successor() override;
    std::string description() const override { return context_.with_renderer("GPU Jacobi CG (float)"); }

private:
    struct Device {
        std::unique_ptr<GpuDiffusionSolver> solver;
        std::vector<std::array<double, 3>> staging;  // interleaved phi for uploads and read-backs
        DeviceRadiance radiance;                     // freed before the solver whose kernels it uses
    };

    GpuFrameContext& context_;
    std::unique_ptr<Device> device_;
    // Device work, applied at the next frame with the context current (a device made later is sent
    // everything).
    PendingChanges pending_;
};

}  // namespace waxwork
