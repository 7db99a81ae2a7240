#include "gl/gl_context.h"

#include "base/error.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace waxwork {

GlApi load_gl_api(GlProcLoader loader) {
    GlApi gl;
#define WAXWORK_GL_LOAD(type, name)                                                           \
    gl.name = reinterpret_cast<type>(loader("gl" #name));                                     \
    if (!gl.name) throw Error("OpenGL: the driver does not provide gl" #name);
    WAXWORK_GL_FUNCTIONS(WAXWORK_GL_LOAD)
#undef WAXWORK_GL_LOAD
    return gl;
}

void check_gl_error(const GlApi& gl, const char* what) {
    const GLenum error = gl.GetError();
    if (error != GL_NO_ERROR) {
        char code[16];
        std::snprintf(code, sizeof code, "0x%04X", error);
        throw Error(std::string(what) + ": OpenGL error " + code);
    }
}

namespace {

template <typename GetIv, typename GetLog>
std::string info_log(GLuint object, GetIv get_iv, GetLog get_log) {
    GLint length = 0;
    get_iv(object, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<size_t>(length > 0 ? length : 0), '\0');
    if (length > 0) get_log(object, length, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log.empty() ? "(the driver gave no log)" : log;
}

}  // namespace

std::string shader_info_log(const GlApi& gl, GLuint shader) {
    return info_log(shader, gl.GetShaderiv, gl.GetShaderInfoLog);
}

std::string program_info_log(const GlApi& gl, GLuint program) {
    return info_log(program, gl.GetProgramiv, gl.GetProgramInfoLog);
}

namespace {

// OSMesa wants a colour buffer to make a context current even when all drawing goes to FBOs.
constexpr int kDefaultBufferSize = 16;

void* osmesa_loader(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }

OSMesaContext create_core_context(int major, int minor) {
    const int attributes[] = {OSMESA_FORMAT, OSMESA_RGBA,
                              OSMESA_DEPTH_BITS, 24,
                              OSMESA_STENCIL_BITS, 0,
                              OSMESA_ACCUM_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION, major,
                              OSMESA_CONTEXT_MINOR_VERSION, minor,
                              0};
    return OSMesaCreateContextAttribs(attributes, nullptr);
}

// What the driver can do when it refused a 4.3 core context: a default (compatibility) context
// reports the version and renderer, for an error message that says what to change.
std::string describe_available_driver() {
    OSMesaContext context = OSMesaCreateContextExt(OSMESA_RGBA, 16, 0, 0, nullptr);
    if (!context) return "OSMesa could not create any context";
    std::vector<unsigned char> buffer(4 * kDefaultBufferSize * kDefaultBufferSize);
    std::string description = "no context could be made current";
    if (OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, kDefaultBufferSize, kDefaultBufferSize)) {
        auto get_string = reinterpret_cast<PFNGLGETSTRINGPROC>(osmesa_loader("glGetString"));
        auto text = [&](GLenum e) {
            const auto* s = get_string ? get_string(e) : nullptr;
            return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
        };
        description = "the driver offers OpenGL " + text(GL_VERSION) + " on " + text(GL_RENDERER);
    }
    OSMesaDestroyContext(context);
    return description;
}

void* egl_loader(const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }

// An OpenGL 4.5 (else 4.3) core context on an initialised EGL display, or EGL_NO_CONTEXT. Without a
// config (EGL_KHR_no_config_context: nothing is drawn to an EGL surface, renderers use FBOs), else with
// any pbuffer-capable OpenGL config (the default surface type, windows, has none without a display).
EGLContext create_egl_core_context(EGLDisplay display) {
    if (!eglBindAPI(EGL_OPENGL_API)) return EGL_NO_CONTEXT;
    std::vector<EGLConfig> configs = {EGL_NO_CONFIG_KHR};
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (eglChooseConfig(display, config_attributes, &config, 1, &count) && count > 0) configs.push_back(config);
    for (EGLConfig candidate : configs)
        for (const EGLint minor : {5, 3}) {
            const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, minor,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
            const EGLContext context = eglCreateContext(display, candidate, EGL_NO_CONTEXT, attributes);
            if (context != EGL_NO_CONTEXT) return context;
        }
    return EGL_NO_CONTEXT;
}

}  // namespace

GlDevice gl_device_from_environment() {
    const char* value = std::getenv("WAXWORK_GL_DEVICE");
    if (!value || !*value || std::string(value) == "osmesa") return GlDevice::OsMesa;
    if (std::string(value) == "egl") return GlDevice::Egl;
    throw Error("WAXWORK_GL_DEVICE=" + std::string(value) + ": expected osmesa or egl");
}

struct HeadlessGlContext::State {
    OSMesaContext context = nullptr;
    std::vector<unsigned char> buffer = std::vector<unsigned char>(4 * kDefaultBufferSize * kDefaultBufferSize);
    EGLDisplay egl_display = EGL_NO_DISPLAY;
    EGLContext egl_context = EGL_NO_CONTEXT;

    // Device displays first (a GPU without a window system), then Mesa's surfaceless platform.
    void create_egl() {
        std::vector<EGLDisplay> candidates;
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        auto platform_display =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        if (query_devices && platform_display) {
            EGLDeviceEXT devices[16];
            EGLint count = 0;
            if (query_devices(16, devices, &count))
                for (EGLint i = 0; i < count; ++i)
                    candidates.push_back(platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr));
        }
        if (platform_display) candidates.push_back(platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr));
        for (EGLDisplay display : candidates) {
            if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr)) continue;
            const EGLContext context = create_egl_core_context(display);
            if (context != EGL_NO_CONTEXT) {
                egl_display = display;
                egl_context = context;
                return;
            }
            eglTerminate(display);
        }
        throw Error("headless OpenGL: no EGL device or surfaceless display gives an OpenGL 4.3 core context (" +
                    std::to_string(candidates.size()) +
                    " displays tried). Unset WAXWORK_GL_DEVICE to use OSMesa (software).");
    }
};

HeadlessGlContext::HeadlessGlContext() : HeadlessGlContext(gl_device_from_environment()) {}

HeadlessGlContext::HeadlessGlContext(GlDevice device) : state_(std::make_unique<State>()), device_(device) {
    if (device == GlDevice::Egl) {
        state_->create_egl();
        make_current();
        gl_ = load_gl_api(egl_loader);
        return;
    }
    // Never overrides a user's choice (overwrite = 0).
    setenv("GALLIUM_DRIVER", "llvmpipe", 0);
    state_->context = create_core_context(4, 5);
    if (!state_->context) state_->context = create_core_context(4, 3);
    if (!state_->context) {
        const char* driver = std::getenv("GALLIUM_DRIVER");
        throw Error("headless OpenGL: OSMesa cannot create an OpenGL 4.3 core context (need >= 4.3; " +
                    describe_available_driver() + "; GALLIUM_DRIVER=" + (driver ? driver : "") +
                    "). Install Mesa's llvmpipe (libosmesa6 built with LLVM) or set GALLIUM_DRIVER=llvmpipe.");
    }
    make_current();
    gl_ = load_gl_api(osmesa_loader);
}

HeadlessGlContext::~HeadlessGlContext() {
    if (!state_) return;
    if (state_->context) OSMesaDestroyContext(state_->context);
    if (state_->egl_context != EGL_NO_CONTEXT) {
        eglMakeCurrent(state_->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(state_->egl_display, state_->egl_context);
        eglTerminate(state_->egl_display);
    }
}

void HeadlessGlContext::make_current() {
    if (state_->egl_context != EGL_NO_CONTEXT) {
        if (!eglMakeCurrent(state_->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->egl_context))
            throw Error("headless OpenGL: eglMakeCurrent failed");
        return;
    }
    if (!OSMesaMakeCurrent(state_->context, state_->buffer.data(), GL_UNSIGNED_BYTE, kDefaultBufferSize,
                           kDefaultBufferSize)) {
        throw Error("headless OpenGL: OSMesaMakeCurrent failed");
    }
}

std::string HeadlessGlContext::version() const {
    const GLubyte* s = gl_.GetString(GL_VERSION);
    return s ? reinterpret_cast<const char*>(s) : "";
}

std::string HeadlessGlContext::renderer() const {
    const GLubyte* s = gl_.GetString(GL_RENDERER);
    return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace waxwork
