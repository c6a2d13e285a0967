// SPDX-License-Identifier: MIT
// A headless OpenGL ES 3 context through EGL.
#include "egl_context.hpp"

#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>

#include <cstring>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace wingman::sim::detail {
namespace {

bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + 1, name)) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

std::string egl_error() { return fmt::format("EGL error 0x{:04x}", eglGetError()); }

// One display for the whole process: eglTerminate would end every context on it, so it is never terminated.
EGLDisplay headless_display() {
  static std::mutex mutex;
  static EGLDisplay display = EGL_NO_DISPLAY;
  static std::string failure;
  std::lock_guard<std::mutex> lock(mutex);
  if (display != EGL_NO_DISPLAY) return display;
  if (!failure.empty()) throw std::runtime_error(failure);

  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  std::string tried;
  EGLDisplay candidate = EGL_NO_DISPLAY;
  EGLint major = 0, minor = 0;
  if (get_platform_display != nullptr && has_extension(client, "EGL_MESA_platform_surfaceless")) {
    candidate = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (candidate != EGL_NO_DISPLAY && eglInitialize(candidate, &major, &minor)) {
      display = candidate;
      return display;
    }
    tried += fmt::format("surfaceless platform: {}; ", egl_error());
  } else {
    tried += "no EGL_MESA_platform_surfaceless; ";
  }
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  if (get_platform_display != nullptr && query_devices != nullptr && has_extension(client, "EGL_EXT_platform_device")) {
    EGLint count = 0;
    query_devices(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(static_cast<size_t>(std::max(count, 0)));
    if (count > 0) query_devices(count, devices.data(), &count);
    for (EGLDeviceEXT device : devices) {
      candidate = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
      if (candidate != EGL_NO_DISPLAY && eglInitialize(candidate, &major, &minor)) {
        display = candidate;
        return display;
      }
    }
    tried += fmt::format("{} EGL device(s), none initialised", count);
  } else {
    tried += "no EGL_EXT_platform_device";
  }
  failure = "no headless EGL display (" + tried +
            "); install Mesa's EGL and llvmpipe (Debian: libegl1 libgl1-mesa-dri) or run where a GPU driver is present";
  throw std::runtime_error(failure);
}

}  // namespace

EglContext::EglContext() {
  display_ = headless_display();
  if (!eglBindAPI(EGL_OPENGL_ES_API)) throw std::runtime_error("EGL: cannot bind the OpenGL ES API: " + egl_error());
  const char* extensions = eglQueryString(display_, EGL_EXTENSIONS);
  if (!has_extension(extensions, "EGL_KHR_surfaceless_context")) {
    throw std::runtime_error("EGL: the display lacks EGL_KHR_surfaceless_context (needed for offscreen rendering)");
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!has_extension(extensions, "EGL_KHR_no_config_context")) {
    const EGLint attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(display_, attributes, &config, 1, &count) || count < 1) {
      throw std::runtime_error("EGL: no OpenGL ES 3 configuration: " + egl_error());
    }
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attributes);
  if (context_ == EGL_NO_CONTEXT)
    throw std::runtime_error("EGL: cannot create an OpenGL ES 3.0 context: " + egl_error());
  make_current();
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  renderer_ = renderer != nullptr ? renderer : "unknown";
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  bool float_buffers = false, float_blend = false;
  for (GLint i = 0; i < count; ++i) {
    const char* name = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
    float_buffers = float_buffers || std::strcmp(name, "GL_EXT_color_buffer_float") == 0;
    float_blend = float_blend || std::strcmp(name, "GL_EXT_float_blend") == 0;
  }
  if (!float_buffers || !float_blend) {
    const std::string missing = !float_buffers ? "GL_EXT_color_buffer_float" : "GL_EXT_float_blend";
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    throw std::runtime_error(
        fmt::format("OpenGL ES renderer '{}' lacks {} (Mesa's llvmpipe has it)", renderer_, missing));
  }
}

EglContext::~EglContext() {
  if (context_ != EGL_NO_CONTEXT) {
    if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
  }
}

void EglContext::make_current() const {
  if (eglGetCurrentContext() == context_) return;
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
    throw std::runtime_error("EGL: cannot make the rendering context current: " + egl_error());
  }
}

}  // namespace wingman::sim::detail
