// The multires method (multires_frame_adapter.h) on the GPU: multires/gpu_multires_solver.h, a device
// copy of the host hierarchy (MultiresHostState). The first frame after a (re)build or a replaced phi
// solves coarse to fine: on the device from zero in a new scene, or, when the host phi is not zero
// (a cut's carried phi, a relaxation's), as its correction computed on the host hierarchy
// (MultiresSolver::set_warm_start), so that both backends start from the same vector; level 0 then
// iterates on the device. Later frames run only the level-0 CG, warm from the resident phi. Painting
// updates the host hierarchy's changed rows first (apply_host_changes), then re-uploads only those rows
// of every level (GpuMultiresSolver::update_rows). The device queue cannot stop part-way: a time budget
// reaches it as an iteration count (FrameSolver::checks_deadline). After a device failure the CPU
// multires goes on with the host hierarchy (cpu_successor).
#pragma once

#include "multires/gpu_multires_solver.h"
#include "scene/device_radiance.h"
#include "scene/frame_solver.h"
#include "scene/gpu_frame_context.h"
#include "scene/multires_frame_adapter.h"
#include "scene/pending_changes.h"

#include <array>
#include <memory>
#include <vector>

namespace waxwork {

class GpuMultiresFrameAdapter : public FrameSolver {
public:
    // `context` outlives this object.
    explicit GpuMultiresFrameAdapter(GpuFrameContext& context) : context_(context) {}
    ~GpuMultiresFrameAdapter() override { context_.free_device_or_leak(device_); }
    GpuMultiresFrameAdapter(const GpuMultiresFrameAdapter&) = delete;
    GpuMultiresFrameAdapter& operator=(const GpuMultiresFrameAdapter&) = delete;

    // Builds the host hierarchy and frees the device copy (made from it at the next frame); throws
    // GpuError when the device copy cannot be freed.
    void matrix_rebuilt(const TetMesh& mesh, const DiffusionMatrix& matrix,
                        std::span<const int32_t> new_of_old_vertex) override;
    void values_changed() override;
    void rows_changed(std::span<const int32_t> rows) override { host_.rows_changed(rows); }
    void right_hand_sides_changed() override;
    void solution_changed() override { host_.solution_changed(); }

    // The host hierarchy first; the rows it changed are queued for the device.
    void apply_host_changes(const DiffusionMatrix& matrix) override;
    FrameResult iterate(const DiffusionMatrix& matrix, const std::array<std::vector<double>, 3>& b,
                        std::array<std::vector<double>, 3>& phi, const FrameLimits& limits, double relative_tolerance,
                        const std::array<bool, 3>& skip) override;
    bool checks_deadline() const override { return false; }
    bool next_frame_measures_iterations() const override {
        return device_ && !device_pending_.all_values && !(host_.solver && host_.pending.solution);
    }

    std::shared_ptr<const GpuBuffer> radiance_on_device(const BoundarySurface& surface, const ShadingSurface& shading,
                                                        const std::vector<std::array<double, 3>>& shading_q,
                                                        std::vector<std::array<float, 3>>* host_copy) override {
        return device_copy_radiance(context_, device_.get(), surface, shading, shading_q, host_copy);
    }
    std::unique_ptr<FrameSolver> cpu_successor() override;

    const MultiresHierarchy* multires_hierarchy() const override {
        return host_.solver ? &host_.solver->hierarchy() : nullptr;
    }
    std::string description() const override {
        return context_.with_renderer("GPU multires, BiCGSTAB coarse to fine, warm CG per frame (float)");
    }

private:
    struct Device {
        std::unique_ptr<GpuMultiresSolver> solver;
        std::vector<std::array<double, 3>> staging;  // interleaved phi for uploads and read-backs
        DeviceRadiance radiance;                     // freed before the solver whose kernels it uses
    };

    GpuFrameContext& context_;
    MultiresHostState host_;
    std::unique_ptr<Device> device_;
    // The device copy's record: all values and b (its warm start follows host_.pending.solution).
    PendingChanges device_pending_;
    // Rows per level the device copy has not received yet (ascending, unique); all of them when
    // device_pending_.all_values.
    std::vector<std::vector<int32_t>> level_rows_;
};

}  // namespace waxwork
