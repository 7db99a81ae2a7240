// Headless OpenGL: an OSMesa (Mesa's off-screen interface, llvmpipe software rasteriser) OpenGL 4.5
// core context, so `waxwork render`, the GPU solver and the tests run without a display or a GPU (or,
// with WAXWORK_GL_DEVICE=egl, an EGL context on a real GPU without a display); and
// the table of OpenGL entry points the renderers and the compute kernels call, loaded from whichever
// context is current. The GPU solver (solver/gpu/) and the renderer (render/) share one device and
// one context, so this platform layer sits below both.
#pragma once

#include <GL/glcorearb.h>

#include <memory>
#include <string>

namespace waxwork {

// Every OpenGL function the renderers and the compute kernels use. Loaded through the context's
// GetProcAddress instead of linking gl* symbols directly: libOSMesa and libGL (GLFW windows) both
// export them, and whichever the dynamic linker binds first would silently receive every call.
#define WAXWORK_GL_FUNCTIONS(X)                                                   \
    X(PFNGLGETSTRINGPROC, GetString)                                              \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                          \
    X(PFNGLGETERRORPROC, GetError)                                                \
    X(PFNGLENABLEPROC, Enable)                                                    \
    X(PFNGLDISABLEPROC, Disable)                                                  \
    X(PFNGLVIEWPORTPROC, Viewport)                                                \
    X(PFNGLCLEARCOLORPROC, ClearColor)                                            \
    X(PFNGLCLEARDEPTHPROC, ClearDepth)                                            \
    X(PFNGLCLEARPROC, Clear)                                                      \
    X(PFNGLDEPTHFUNCPROC, DepthFunc)                                              \
    X(PFNGLREADPIXELSPROC, ReadPixels)                                            \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                          \
    X(PFNGLFINISHPROC, Finish)                                                    \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                                  \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                            \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                                  \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                  \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                    \
    X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)                                  \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)                                \
    X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                          \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                \
    X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                          \
    X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)    \
    X(PFNGLCREATESHADERPROC, CreateShader)                                        \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                        \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                      \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                          \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                                \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                        \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                      \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                        \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                          \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                        \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                              \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                      \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                            \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                            \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                              \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                              \
    X(PFNGLUNIFORM2FPROC, Uniform2f)                                              \
    X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                            \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                            \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                                \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                                  \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                            \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                                  \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                                            \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                      \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                            \
    X(PFNGLBUFFERDATAPROC, BufferData)                                            \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)                  \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                          \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                                        \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                                            \
    X(PFNGLGENTEXTURESPROC, GenTextures)                                          \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                    \
    X(PFNGLBINDTEXTUREPROC, BindTexture)                                          \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                      \
    X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                            \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                      \
    X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                                  \
    X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                      \
    X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                    \
    X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                                      \
    X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                                \
    X(PFNGLCOPYBUFFERSUBDATAPROC, CopyBufferSubData)                              \
    X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                            \
    X(PFNGLUNIFORM3UIVPROC, Uniform3uiv)

struct GlApi {
#define WAXWORK_GL_DECLARE(type, name) type name = nullptr;
    WAXWORK_GL_FUNCTIONS(WAXWORK_GL_DECLARE)
#undef WAXWORK_GL_DECLARE
};

using GlProcLoader = void* (*)(const char* name);

// Resolves every entry of GlApi ("gl" + name) with `loader` for the current context. Throws
// waxwork::Error naming the first missing function.
GlApi load_gl_api(GlProcLoader loader);

// Throws waxwork::Error("WHAT: OpenGL error 0x...") when glGetError reports one.
void check_gl_error(const GlApi& gl, const char* what);

// The driver's info log of a shader or a program (after a failed compile or link), without trailing
// newlines; "(the driver gave no log)" when it is empty.
std::string shader_info_log(const GlApi& gl, GLuint shader);
std::string program_info_log(const GlApi& gl, GLuint program);

// Where a HeadlessGlContext comes from.
enum class GlDevice {
    // Mesa's OSMesa: always software (llvmpipe), needs no display, no GPU and no driver setup. The
    // default: tests and `waxwork render` give the same pixels on every machine.
    OsMesa,
    // EGL without a window system: the first EGL device that gives an OpenGL 4.3 core context
    // (EGL_EXT_platform_device: a GPU's driver, e.g. NVIDIA's or Mesa's on /dev/dri/renderD*), else
    // Mesa's surfaceless platform. This is how the GPU solver and its benchmark reach a real GPU on a
    // machine without a display; on this machine it finds llvmpipe again.
    Egl,
};

// The device the environment asks for: WAXWORK_GL_DEVICE=egl selects Egl, unset or "osmesa" OsMesa.
// Throws waxwork::Error for any other value.
GlDevice gl_device_from_environment();

// An off-screen OpenGL context, current on the creating thread from construction on. It has only a
// tiny default framebuffer (OSMesa) or none (EGL): renderers draw into their own framebuffer objects.
//
// Asks for OpenGL 4.5 core, then 4.3 core (the minimum: the shaders are GLSL 4.30). OSMesa: if
// GALLIUM_DRIVER is unset it is set to "llvmpipe" first: softpipe, Mesa's other software driver,
// stops at OpenGL 3.3. Throws waxwork::Error explaining what the driver offers when neither version
// can be created.
class HeadlessGlContext {
public:
    // The device of gl_device_from_environment().
    HeadlessGlContext();
    explicit HeadlessGlContext(GlDevice device);
    ~HeadlessGlContext();
    HeadlessGlContext(const HeadlessGlContext&) = delete;
    HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

    // Makes the context current on the calling thread (one context per thread at a time).
    void make_current();
    const GlApi& gl() const { return gl_; }
    // "4.5 (Core Profile) Mesa 22.3.6", "llvmpipe (LLVM 15.0.6, 256 bits)".
    std::string version() const;
    std::string renderer() const;
    GlDevice device() const { return device_; }

private:
    struct State;
    std::unique_ptr<State> state_;
    GlApi gl_;
    GlDevice device_ = GlDevice::OsMesa;
};

}  // namespace waxwork
