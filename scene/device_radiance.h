// The exitant radiance factor E (Eq. 3 without F_t, gpu_radiance.h) of every shading vertex, computed
// on the device from a device solver's resident phi, for a renderer in the context's share group
// (LiveSolver::radiance_on_device). Keeps the rows, eta and q it was built and lit with, and rebuilds or
// re-lights only when those differ (a new surface or shading, a painted eta, a new light).
#pragma once

#include "scene/gpu_frame_context.h"
#include "solver/gpu/gpu_radiance.h"

#include <array>
#include <memory>
#include <vector>

namespace waxwork {

class DeviceRadiance {
public:
    // E from `phi` (the device solver's solution buffer: 3 floats per volume vertex, n vertices, on
    // `kernels`), 3 floats per shading vertex in a new buffer (the renderer may still draw the
    // previous one), complete when returned. Null without a context or shading vertices. `host_copy`,
    // when given, receives the same E read back. Throws InvalidArgumentError unless shading_q has one
    // value per shading vertex, GpuError when the device fails.
    std::shared_ptr<const GpuBuffer> compute(GpuFrameContext& context, GpuKernels& kernels, const GpuBuffer& phi,
                                             size_t n, const BoundarySurface& surface, const ShadingSurface& shading,
                                             const std::vector<std::array<double, 3>>& shading_q,
                                             std::vector<std::array<float, 3>>* host_copy);

private:
    std::unique_ptr<GpuRadiance> radiance_;
    RadianceRows rows_;
    std::vector<std::array<double, 3>> q_;
};

// FrameSolver::radiance_on_device of a GPU frame solver whose device copy `device` (null until made)
// holds a `solver` (with kernels(), solution_buffer() and size()) and its DeviceRadiance `radiance`:
// E from the solver's resident phi, or null without a device copy.
template <class Device>
std::shared_ptr<const GpuBuffer> device_copy_radiance(GpuFrameContext& context, Device* device,
                                                      const BoundarySurface& surface, const ShadingSurface& shading,
                                                      const std::vector<std::array<double, 3>>& shading_q,
                                                      std::vector<std::array<float, 3>>* host_copy) {
    if (!device) return nullptr;
    auto& solver = *device->solver;
    return device->radiance.compute(context, solver.kernels(), solver.solution_buffer(), solver.size(), surface,
                                    shading, shading_q, host_copy);
}

}  // namespace waxwork
