#include "gl/gpu_compute.h"

#include <cstdio>
#include <cstdlib>
#include <utility>

namespace waxwork {

void require_compute_support(const GlApi& gl) {
    GLint major = 0, minor = 0;
    gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    if (major < 4 || (major == 4 && minor < 3)) {
        const GLubyte* version = gl.GetString(GL_VERSION);
        throw GpuError("GPU solver: needs OpenGL 4.3 (compute shaders), the context offers " +
                       std::string(version ? reinterpret_cast<const char*>(version) : "an unknown version"));
    }
}

bool gpu_failure_forced_for(const std::string& shader_name) {
    const char* forced = std::getenv("WAXWORK_GPU_FORCE_FAIL");
    if (!forced || !*forced) return false;
    const std::string value(forced);
    return value == "1" || value == shader_name;
}

void check_gpu_error(const GlApi& gl, const char* what) {
    const GLenum error = gl.GetError();
    if (error != GL_NO_ERROR) {
        char code[16];
        std::snprintf(code, sizeof code, "0x%04X", error);
        throw GpuError(std::string("GPU solver: ") + what + ": OpenGL error " + code);
    }
}

// --- GpuBuffer ----------------------------------------------------------------------------------

GpuBuffer::GpuBuffer(const GlApi& gl, size_t bytes, const void* data) : gl_(&gl), bytes_(bytes) {
    gl.GenBuffers(1, &id_);
    gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, id_);
    // Zero-sized buffers cannot be bound as storage ranges on some drivers: keep at least 16 bytes.
    const size_t allocated = bytes < 16 ? 16 : bytes;
    gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(allocated), nullptr, GL_DYNAMIC_DRAW);
    if (data && bytes > 0) gl.BufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data);
    check_gpu_error(gl, "allocating a storage buffer");
}

GpuBuffer::~GpuBuffer() {
    if (gl_ && id_) gl_->DeleteBuffers(1, &id_);
}

GpuBuffer::GpuBuffer(GpuBuffer&& other) noexcept
    : gl_(other.gl_), id_(std::exchange(other.id_, 0)), bytes_(std::exchange(other.bytes_, 0)) {}

GpuBuffer& GpuBuffer::operator=(GpuBuffer&& other) noexcept {
    if (this != &other) {
        if (gl_ && id_) gl_->DeleteBuffers(1, &id_);
        gl_ = other.gl_;
        id_ = std::exchange(other.id_, 0);
        bytes_ = std::exchange(other.bytes_, 0);
    }
    return *this;
}

void GpuBuffer::write(size_t offset, size_t bytes, const void* data) {
    if (bytes == 0) return;
    if (offset + bytes > bytes_) throw InvalidArgumentError("GpuBuffer::write: range beyond the buffer");
    gl_->BindBuffer(GL_SHADER_STORAGE_BUFFER, id_);
    gl_->BufferSubData(GL_SHADER_STORAGE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}

void GpuBuffer::read(size_t offset, size_t bytes, void* data) const {
    if (bytes == 0) return;
    if (offset + bytes > bytes_) throw InvalidArgumentError("GpuBuffer::read: range beyond the buffer");
    gl_->BindBuffer(GL_SHADER_STORAGE_BUFFER, id_);
    gl_->GetBufferSubData(GL_SHADER_STORAGE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                          data);
}

void GpuBuffer::copy_from(const GpuBuffer& source) {
    if (source.bytes_ != bytes_) throw InvalidArgumentError("GpuBuffer::copy_from: sizes differ");
    if (bytes_ == 0) return;
    gl_->BindBuffer(GL_COPY_READ_BUFFER, source.id_);
    gl_->BindBuffer(GL_COPY_WRITE_BUFFER, id_);
    gl_->CopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0, static_cast<GLsizeiptr>(bytes_));
}

void GpuBuffer::bind(GLuint binding) const { gl_->BindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id_); }

// --- ComputeProgram -----------------------------------------------------------------------------

namespace {

// Driver logs span lines; the caller prints one line.
std::string one_line(std::string text) {
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ' ';
    return text;
}

}  // namespace

ComputeProgram::ComputeProgram(const GlApi& gl, std::string name, const std::string& source)
    : gl_(&gl), name_(std::move(name)) {
    const std::string text = gpu_failure_forced_for(name_) ? source + "\n#error forced by WAXWORK_GPU_FORCE_FAIL\n"
                                                           : source;
    const GLuint shader = gl.CreateShader(GL_COMPUTE_SHADER);
    if (!shader) throw GpuError("GPU solver: cannot create compute shader " + name_ + " (no compute support?)");
    const char* sources[] = {text.c_str()};
    gl.ShaderSource(shader, 1, sources, nullptr);
    gl.CompileShader(shader);
    GLint ok = 0;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        const std::string log = shader_info_log(gl, shader);
        gl.DeleteShader(shader);
        throw GpuError("GPU solver: compute shader " + name_ + " failed to compile: " + one_line(log));
    }
    id_ = gl.CreateProgram();
    gl.AttachShader(id_, shader);
    gl.LinkProgram(id_);
    gl.DeleteShader(shader);  // flagged; freed with the program
    gl.GetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (!ok) {
        const std::string log = program_info_log(gl, id_);
        gl.DeleteProgram(std::exchange(id_, 0));
        throw GpuError("GPU solver: compute shader " + name_ + " failed to link: " + one_line(log));
    }
}

ComputeProgram::~ComputeProgram() {
    if (gl_ && id_) gl_->DeleteProgram(id_);
}

ComputeProgram::ComputeProgram(ComputeProgram&& other) noexcept
    : gl_(other.gl_), id_(std::exchange(other.id_, 0)), name_(std::move(other.name_)) {}

ComputeProgram& ComputeProgram::operator=(ComputeProgram&& other) noexcept {
    if (this != &other) {
        if (gl_ && id_) gl_->DeleteProgram(id_);
        gl_ = other.gl_;
        id_ = std::exchange(other.id_, 0);
        name_ = std::move(other.name_);
    }
    return *this;
}

void ComputeProgram::use() const { gl_->UseProgram(id_); }

GLint ComputeProgram::uniform(const char* name) const { return gl_->GetUniformLocation(id_, name); }

void ComputeProgram::dispatch(GLuint groups) const {
    if (groups == 0) return;
    gl_->DispatchCompute(groups, 1, 1);
    // Storage writes visible to the next dispatch; buffer-update for reads and sub-data writes.
    gl_->MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

}  // namespace waxwork
