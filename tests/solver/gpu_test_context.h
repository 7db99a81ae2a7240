// The OpenGL context of the GPU tests: one per test executable, skipped with the reason where this
// machine cannot give OpenGL 4.3 (Mesa's llvmpipe through OSMesa gives 4.5 in CI).
#pragma once

#include "gl/gl_context.h"
#include "gl/gpu_compute.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace waxwork::testing {

// One context for the whole suite (creating an OSMesa context costs ~50 ms); nullptr with the reason
// when this machine cannot give OpenGL 4.3.
inline HeadlessGlContext* gl_context(std::string& why) {
    static std::unique_ptr<HeadlessGlContext> context;
    static std::string failure;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            context = std::make_unique<HeadlessGlContext>();
            require_compute_support(context->gl());
        } catch (const Error& e) {
            failure = e.what();
            context.reset();
        }
    }
    why = failure;
    if (context) context->make_current();
    return context.get();
}

#define WAXWORK_REQUIRE_GL(context)                                              \
    std::string gl_skip_reason;                                                  \
    HeadlessGlContext* context = ::waxwork::testing::gl_context(gl_skip_reason); \
    if (!context) GTEST_SKIP() << "no OpenGL 4.3 context: " << gl_skip_reason

}  // namespace waxwork::testing
