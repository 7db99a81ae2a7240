#include "scene/device_radiance.h"

#include "base/error.h"

namespace waxwork {

std::shared_ptr<const GpuBuffer> DeviceRadiance::compute(GpuFrameContext& context, GpuKernels& kernels,
                                                         const GpuBuffer& phi, size_t n, const BoundarySurface& surface,
                                                         const ShadingSurface& shading,
                                                         const std::vector<std::array<double, 3>>& shading_q,
                                                         std::vector<std::array<float, 3>>* host_copy) {
    if (!context.get() || shading.size() == 0) return nullptr;
    const size_t m = shading.size();
    if (shading_q.size() != m)
        throw InvalidArgumentError("live solver: radiance_on_device needs one light value per shading vertex");
    RadianceRows rows = shading_radiance_rows(surface, shading);
    const CurrentContext current(*context.get());
    const GlApi& gl = context.get()->gl();
    if (!radiance_ || rows_ != rows) {
        radiance_.reset();  // frees its buffers with the context current
        radiance_ = std::make_unique<GpuRadiance>(kernels, rows, n);
        rows_ = std::move(rows);
        q_.clear();
    }
    if (q_ != shading_q) {
        radiance_->set_light(shading_q);
        q_ = shading_q;
    }
    auto e = std::make_shared<GpuBuffer>(gl, 3 * m * sizeof(float));
    radiance_->compute(phi, *e);
    if (host_copy) {
        const std::vector<float> values = e->download<float>();
        host_copy->resize(m);
        for (size_t s = 0; s < m; ++s)
            for (size_t c = 0; c < 3; ++c) (*host_copy)[s][c] = values[3 * s + c];
    }
    check_gpu_error(gl, "computing the radiance on the device");
    // The main window's context reads it next: the writes must be complete (a shared object's changes
    // are visible to another context only after the writing context finished them).
    gl.Finish();
    return e;
}

}  // namespace waxwork
