// SPDX-License-Identifier: MIT
// A headless OpenGL ES 3 context through EGL (Mesa's surfaceless platform, else an EGL device): no window system.
#pragma once

#include <EGL/egl.h>

#include <string>

namespace wingman::sim::detail {

/// Owns one OpenGL ES 3 context on the process's headless EGL display. Rendering goes to framebuffer objects only.
/// Not copyable or movable (GL objects belong to the context).
class EglContext {
 public:
  /// Throws std::runtime_error with one line naming what failed (no EGL display, no ES 3 context, a missing
  /// extension).
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes the context current on the calling thread (cheap when it already is).
  void make_current() const;
  /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& renderer() const { return renderer_; }

 private:
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  std::string renderer_;
};

}  // namespace wingman::sim::detail
