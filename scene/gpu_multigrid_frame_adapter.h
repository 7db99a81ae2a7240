// The GPU multigrid CG as a frame solver: multires/gpu_multigrid_frame_solver.h, the CPU multigrid
// CG's algorithm (multigrid_frame.h) with phi, r, p, q and the V-cycle's levels on the device (float).
// The hierarchy and the Galerkin operators are built on the host at the first GPU frame after a
// (re)build, from the rest positions kept by matrix_rebuilt; after an edit with a vertex map they are
// rebuilt at matrix_rebuilt from the previous ones (the ones still waiting here, or the device
// solver's), on the host, for the device solver built at the next frame. Painting uploads the
// recomputed rows of every level. A time limit is checked between V-cycles (each CG step reads back
// its sums anyway, so no prediction is needed).
//
// After a device failure the CPU multigrid CG goes on (cpu_successor); when the V-cycle cannot be
// built or applied (AlgorithmError), LiveSolver runs GPU Jacobi CG instead.
#pragma once

#include "multires/gpu_multigrid_frame_solver.h"
#include "multires/multigrid_preconditioner.h"
#include "scene/device_radiance.h"
#include "scene/gpu_frame_context.h"
#include "scene/multigrid_frame_adapter_base.h"

#include <memory>

namespace waxwork {

class GpuMultigridFrameAdapter : public MultigridFrameAdapterBase {
public:
    // `context` outlives this object.
    GpuMultigridFrameAdapter(GpuFrameContext& context, const MultigridOptions& options)
        : MultigridFrameAdapterBase(options), context_(context) {}
    ~GpuMultigridFrameAdapter() override { context_.free_device_or_leak(device_); }
    GpuMultigridFrameAdapter(const GpuMultigridFrameAdapter&) = delete;
    GpuMultigridFrameAdapter& operator=(const GpuMultigridFrameAdapter&) = delete;

    // Keeps the rest positions (and the operators rebuilt around the edit) for the next frame's device
    // solver and frees the device copy; throws GpuError when it cannot be freed.
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override;

    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;

    std::shared_ptr<const GpuBuffer> radiance_on_device(const BoundarySurface& surface, const ShadingSurface& shading,
                                                        const std::vector<std::array<double, 3>>& shading_q,
                                                        std::vector<std::array<float, 3>>* host_copy) override {
        return device_copy_radiance(context_, device_.get(), surface, shading, shading_q, host_copy);
    }
    std::unique_ptr<FrameSolver> cpu_successor() override;

    // The operators waiting for the next frame's device solver, else the device solver's.
    const MultiresHierarchy* multires_hierarchy() const override;
    const MultigridPreconditioner* multigrid_preconditioner() const override;
    std::string description() const override;

private:
    struct Device {
        std::unique_ptr<GpuMultigridFrameSolver> solver;
        DeviceRadiance radiance;  // freed before the solver whose kernels it uses
    };
    bool has_solver() const override { return device_ != nullptr; }

    // positions_: kept from matrix_rebuilt for the device solver built at the next frame and for a CPU
    // multigrid after a fallback (empty on an empty matrix); waiting_: the operators rebuilt around an
    // edit, for that device solver; pending_: the device's record.
    GpuFrameContext& context_;
    std::unique_ptr<Device> device_;
};

}  // namespace waxwork
