// The editor's GPU solver context: a hidden GLFW window whose OpenGL context shares objects with the
// main window's (glfwCreateWindow's `share`), so the buffers the solver fills on the worker thread are
// the buffers the main window's renderer can read. Each worker tick makes it current on its thread and
// releases it at the end (LiveSolver does both around every GPU call).
#pragma once

#include "gl/shared_context.h"

#include <memory>
#include <string>

struct GLFWwindow;

namespace waxwork {

// Main thread only (GLFW creates and destroys windows there); the returned context must also be
// destroyed on the main thread, before `main_window`. Returns null and sets `error` when the driver
// gives no shared OpenGL 4.3 core context.
std::shared_ptr<SolverGlContext> open_shared_window_context(GLFWwindow* main_window, std::string& error);

}  // namespace waxwork
