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

}  // namespace waxwork
