// SPDX-License-Identifier: MIT
// A linked OpenGL ES shader program and GL error checks.
#pragma once

#include <GLES3/gl3.h>

#include <string>

namespace wingman::sim::detail {

/// Owns a linked program (vertex + fragment shader, GLSL ES 3.00). Needs a current context for its whole life.
class GlProgram {
 public:
  /// Compiles and links; throws std::runtime_error with `name` and the compiler's log on failure.
  GlProgram(const std::string& name, const std::string& vertex_source, const std::string& fragment_source);
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  GLuint id() const { return id_; }
  /// The uniform's location; throws std::runtime_error if the program has no such active uniform.
  GLint uniform(const char* name) const;

 private:
  std::string name_;
  GLuint id_ = 0;
};

/// Throws std::runtime_error "OpenGL error 0x.... after <what>" if glGetError reports one.
void check_gl(const char* what);

}  // namespace wingman::sim::detail
