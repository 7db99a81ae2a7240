#include "editor/window_gl_context.h"

#include "base/error.h"

#include <GLFW/glfw3.h>

namespace waxwork {
namespace {

void* window_proc_address(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

class SharedWindowContext : public SolverGlContext {
public:
    explicit SharedWindowContext(GLFWwindow* window) : window_(window) {}
    ~SharedWindowContext() override { glfwDestroyWindow(window_); }
    // Restores what was current before (the main window's context when the main thread frees the
    // solver's buffers; none on a worker).
    void make_current() override {
        previous_ = glfwGetCurrentContext();
        glfwMakeContextCurrent(window_);
    }
    void release() override { glfwMakeContextCurrent(previous_ == window_ ? nullptr : previous_); }
    const GlApi& gl() const override { return gl_; }
    void load() { gl_ = load_gl_api(window_proc_address); }

private:
    GLFWwindow* window_;
    GlApi gl_;
    static thread_local GLFWwindow* previous_;
};

thread_local GLFWwindow* SharedWindowContext::previous_ = nullptr;

}  // namespace

std::shared_ptr<SolverGlContext> open_shared_window_context(GLFWwindow* main_window, std::string& error) {
    // The same hints as the main window (editor_app.cpp), hidden: a context needs a window in GLFW, but
    // nobody draws into this one.
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    GLFWwindow* window = nullptr;
    for (const int minor : {5, 3}) {
        glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
        glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, minor);
        window = glfwCreateWindow(16, 16, "Waxwork solver", nullptr, main_window);
        if (window) break;
    }
    glfwWindowHint(GLFW_VISIBLE, GLFW_TRUE);
    if (!window) {
        const char* description = nullptr;
        glfwGetError(&description);
        error = std::string("no shared OpenGL 4.3 context for the GPU solver: ") +
                (description ? description : "GLFW gave no reason");
        return nullptr;
    }
    auto context = std::make_shared<SharedWindowContext>(window);
    // Entry points are loaded with the context current; the main window's is restored after.
    GLFWwindow* previous = glfwGetCurrentContext();
    glfwMakeContextCurrent(window);
    try {
        context->load();
    } catch (const Error& e) {
        glfwMakeContextCurrent(previous);
        error = e.what();
        return nullptr;
    }
    glfwMakeContextCurrent(previous);
    return context;
}

}  // namespace waxwork
