// An OpenGL context that work may use from any thread, one thread at a time: the GPU solver's
// context, which is either the window's hidden shared context (editor/window_gl_context.h) or a
// headless OSMesa/EGL one (gl_context.h) for tests and `waxwork run`.
#pragma once

#include "gl/gl_context.h"

#include <memory>

namespace waxwork {

// An OpenGL >= 4.3 context the GPU solver may use from any thread, one thread at a time.
class SolverGlContext {
public:
    virtual ~SolverGlContext() = default;
    // Makes the context current on the calling thread.
    virtual void make_current() = 0;
    // The calling thread is done with it for now (a GLFW context must not stay current on a thread
    // that ends while another thread may take it next). Default: nothing.
    virtual void release() {}
    virtual const GlApi& gl() const = 0;
};

// An OSMesa/EGL context (gl_context.h) as a SolverGlContext: owned (opened here) or borrowed (the
// caller's, e.g. the one `waxwork run` renders with, which must then outlive this object).
std::shared_ptr<SolverGlContext> open_headless_solver_context();  // throws waxwork::Error
std::shared_ptr<SolverGlContext> borrow_headless_solver_context(HeadlessGlContext& context);

// Makes a context current for one scope and releases it afterwards (also when a GL call throws).
class CurrentContext {
public:
    explicit CurrentContext(SolverGlContext& context) : context_(context) { context_.make_current(); }
    ~CurrentContext() { context_.release(); }
    CurrentContext(const CurrentContext&) = delete;
    CurrentContext& operator=(const CurrentContext&) = delete;

private:
    SolverGlContext& context_;
};

}  // namespace waxwork
