// SPDX-License-Identifier: MIT
// A linked OpenGL ES shader program and GL error checks.
#include "gl_program.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <vector>

namespace wingman::sim::detail {
namespace {

GLuint compile(const std::string& program, GLenum type, const std::string& source) {
  const GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<size_t>(std::max(length, 1)));
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    throw std::runtime_error(fmt::format("{} {} shader does not compile: {}", program,
                                         type == GL_VERTEX_SHADER ? "vertex" : "fragment", log.data()));
  }
  return shader;
}

}  // namespace

GlProgram::GlProgram(const std::string& name, const std::string& vertex_source, const std::string& fragment_source)
    : name_(name) {
  const GLuint vs = compile(name, GL_VERTEX_SHADER, vertex_source);
  GLuint fs = 0;
  try {
    fs = compile(name, GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &length);
    std::vector<char> log(static_cast<size_t>(std::max(length, 1)));
    glGetProgramInfoLog(id_, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(id_);
    throw std::runtime_error(fmt::format("{} program does not link: {}", name, log.data()));
  }
}

GlProgram::~GlProgram() {
  if (id_ != 0) glDeleteProgram(id_);
}

GLint GlProgram::uniform(const char* name) const {
  const GLint location = glGetUniformLocation(id_, name);
  if (location < 0) throw std::runtime_error(fmt::format("{} program has no active uniform '{}'", name_, name));
  return location;
}

void check_gl(const char* what) {
  const GLenum error = glGetError();
  if (error != GL_NO_ERROR) throw std::runtime_error(fmt::format("OpenGL error 0x{:04x} after {}", error, what));
}

}  // namespace wingman::sim::detail
