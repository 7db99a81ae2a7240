#include "solver/gl_context.h"

#include "tetops/error.h"

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

}  // namespace

struct HeadlessGlContext::State {
    OSMesaContext context = nullptr;
    std::vector<unsigned char> buffer = std::vector<unsigned char>(4 * kDefaultBufferSize * kDefaultBufferSize);
};

HeadlessGlContext::HeadlessGlContext() : state_(std::make_unique<State>()) {
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
    if (state_ && state_->context) OSMesaDestroyContext(state_->context);
}

void HeadlessGlContext::make_current() {
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
