// The small OpenGL compute layer under the GPU solver: shader storage buffers, compute programs built
// from GLSL 4.30 source, and the error that tells a caller to fall back to the CPU path.
//
// Everything needs the context that `gl` was loaded from to be current on the calling thread, and
// every object must be destroyed while it is still current.
#pragma once

#include "base/error.h"
#include "gl/gl_context.h"

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace waxwork {

// The GPU path cannot run here: no OpenGL 4.3 (compute shaders and storage buffers), a shader that
// does not compile or link (what() names the shader and quotes the driver's log), or an OpenGL error
// while solving. Callers catch it and solve on the CPU instead; it never means a wrong result.
class GpuError : public Error {
public:
    using Error::Error;
};

// Throws GpuError unless the current context is OpenGL >= 4.3 (compute shaders, SSBOs, GLSL 4.30).
void require_compute_support(const GlApi& gl);

// Test hook: when the environment variable WAXWORK_GPU_FORCE_FAIL is set (to a shader name, or to
// "1" for every shader), that shader's source is corrupted before compilation, so the real driver
// rejects it and the whole failure path (log, GpuError, CPU fallback) runs as it would on a bad driver.
bool gpu_failure_forced_for(const std::string& shader_name);

// One shader storage buffer (GL_SHADER_STORAGE_BUFFER, std430 arrays). Move-only.
class GpuBuffer {
public:
    GpuBuffer() = default;
    GpuBuffer(const GlApi& gl, size_t bytes, const void* data = nullptr);
    ~GpuBuffer();
    GpuBuffer(GpuBuffer&& other) noexcept;
    GpuBuffer& operator=(GpuBuffer&& other) noexcept;
    GpuBuffer(const GpuBuffer&) = delete;
    GpuBuffer& operator=(const GpuBuffer&) = delete;

    template <typename T>
    static GpuBuffer from(const GlApi& gl, std::span<const T> data) {
        return GpuBuffer(gl, data.size_bytes(), data.data());
    }
    // Writes/reads `bytes` at byte `offset` (a read waits for the dispatches that write the buffer).
    void write(size_t offset, size_t bytes, const void* data);
    void read(size_t offset, size_t bytes, void* data) const;
    template <typename T>
    std::vector<T> download() const {
        std::vector<T> out(bytes_ / sizeof(T));
        read(0, out.size() * sizeof(T), out.data());
        return out;
    }
    // Copies all of `source` (same size) on the device.
    void copy_from(const GpuBuffer& source);
    void bind(GLuint binding) const;

    GLuint id() const { return id_; }
    size_t bytes() const { return bytes_; }

private:
    const GlApi* gl_ = nullptr;
    GLuint id_ = 0;
    size_t bytes_ = 0;
};

// A compute program linked from one GLSL source. Move-only.
class ComputeProgram {
public:
    ComputeProgram() = default;
    // Throws GpuError("GPU solver: compute shader NAME failed to compile: LOG") (or "to link").
    ComputeProgram(const GlApi& gl, std::string name, const std::string& source);
    ~ComputeProgram();
    ComputeProgram(ComputeProgram&& other) noexcept;
    ComputeProgram& operator=(ComputeProgram&& other) noexcept;
    ComputeProgram(const ComputeProgram&) = delete;
    ComputeProgram& operator=(const ComputeProgram&) = delete;

    // Makes the program current (glUseProgram) for uniform calls and dispatch.
    void use() const;
    // Uniform location; -1 (ignored by glUniform*) when the compiler removed an unused uniform.
    GLint uniform(const char* name) const;
    // Dispatches `groups` workgroups and issues the storage barrier the next dispatch or read needs.
    void dispatch(GLuint groups) const;
    const std::string& name() const { return name_; }

private:
    const GlApi* gl_ = nullptr;
    GLuint id_ = 0;
    std::string name_;
};

// Throws GpuError("GPU solver: WHAT: OpenGL error 0x...") when glGetError reports one.
void check_gpu_error(const GlApi& gl, const char* what);

}  // namespace waxwork
