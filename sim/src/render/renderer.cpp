// SPDX-License-Identifier: MIT
// Renderer: drones into a supersampled pinhole layer, composited over a procedural scene through the lens map,
// motion blur by accumulation, then exposure, sRGB, noise and quantisation; exact truth boxes alongside.
#include "wingman/sim/renderer.hpp"

#include "colour.hpp"
#include "egl_context.hpp"
#include "gl_program.hpp"
#include "lens_map.hpp"
#include "shaders.hpp"

#include <GLES3/gl3.h>
#include <fmt/format.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace wingman::sim {
namespace {

constexpr double kNearM = 0.05;   // near clipping distance of the drone layer, metres
constexpr double kFarM = 5000.0;  // far clipping distance, metres
constexpr double kMaxLayerPixels = 24e6;
static_assert(kMaxPropellers + 1 == 17, "kDroneVertexShader declares u_cam_from_part[17]");
constexpr uint64_t kEvictAfterFrames = 16;  // GPU copies of models unused for this many frames are freed
// Texture units.
constexpr GLint kMapUnit = 0, kLayerUnit = 1, kNoiseUnit = 2, kIdsUnit = 3, kAccumUnit = 4, kBackgroundUnit = 5,
                kCentresUnit = 6;
constexpr double kDefaultLightLevel = 0.45 + 0.6427876;  // ambient + sin(40 deg): the default options' light

// Pixel rectangle [x0, x1) x [y0, y1) in the pinhole layer.
struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

Rect expanded(const Rect& r, int margin, int width, int height) {
  if (r.empty()) return r;
  return {std::max(r.x0 - margin, 0), std::max(r.y0 - margin, 0), std::min(r.x1 + margin, width),
          std::min(r.y1 + margin, height)};
}

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// A standard normal number from a seed (Box-Muller on splitmix64; the same on every platform).
double normal_from_seed(uint64_t seed) {
  const uint64_t a = splitmix64(seed), b = splitmix64(a);
  const double u1 = (static_cast<double>(a >> 11) + 0.5) * 0x1.0p-53;
  const double u2 = (static_cast<double>(b >> 11) + 0.5) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

Eigen::Isometry3d advance(const Eigen::Isometry3d& T, const Eigen::Vector3d& v_in_world,
                          const Eigen::Vector3d& w_in_local, double t) {
  if (t == 0.0) return T;
  Eigen::Isometry3d out = T;
  out.translation() += v_in_world * t;
  const Eigen::Vector3d rotation = w_in_local * t;
  if (rotation.norm() > 0.0)
    out.linear() = T.linear() * Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix();
  return out;
}

double luma(const Eigen::Vector3d& c) { return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z(); }

Eigen::Vector3d unit_luma(const Eigen::Vector3d& c) { return c / std::max(luma(c), 1e-6); }

void set3(GLint location, const Eigen::Vector3d& v) {
  glUniform3f(location, static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
}

struct GpuModel {
  GLuint vao = 0, vbo = 0, ibo = 0;
  GLsizei opaque = 0, total = 0;
  uint64_t last_used = 0;
};

// One drone at one instant of the exposure.
struct Posed {
  size_t index;  // in render()'s drones
  const DroneModel* model;
  Eigen::Isometry3d T_body_to_cam;
  double prop_angle_rad;
};

}  // namespace

struct Renderer::Impl {
  geometry::CameraModel camera;
  RenderOptions options;
  TruthBoxProjector projector;
  // The GL context: this renderer's own, or shared with other cameras' renderers (one context for a whole rig). Every
  // pass sets the GL state it needs, so renderers sharing a context do not disturb one another.
  std::shared_ptr<detail::EglContext> egl;
  std::optional<detail::GlProgram> drone_program;
  // The full-screen passes are compiled per variant of the options (llvmpipe runs every branch of a shader, so what
  // is off is compiled out): name and "#define" lines -> program.
  std::map<std::string, std::unique_ptr<detail::GlProgram>> variants;
  const detail::GlProgram* background_program = nullptr;  // sky, ground, trees per block of pixels
  const detail::GlProgram* compose_program = nullptr;     // background through the sensor (LAYER 0)
  const detail::GlProgram* drones_program = nullptr;      // with the drone layer over it (LAYER 1)
  const detail::GlProgram* final_program = nullptr;       // the sensor on accumulated motion-blur samples
  GLuint noise_tex = 0;
  int64_t noise_seed = 0;                                   // the seed noise_tex was made from
  Eigen::Vector3d sun_in_world = Eigen::Vector3d::UnitZ();  // unit vector to the sun, ENU

  // Lens and pinhole layer.
  Eigen::Vector2d n0 = Eigen::Vector2d::Zero();  // normalized coordinates of the layer's corner
  double fp = 1.0;                               // layer pixels per normalized unit
  int layer_w = 0, layer_h = 0;
  GLuint map_tex = 0, centres_tex = 0, layer_fbo = 0, layer_colour = 0, layer_ids = 0, layer_depth = 0;
  GLuint accum_fbo = 0, accum_tex = 0, out_fbo = 0, out_rb = 0, empty_vao = 0;
  GLuint bg_fbo = 0, bg_tex = 0;  // the background pass, one texel per background_subsampling^2 pixels
  int bg_w = 0, bg_h = 0;
  std::unordered_map<uint64_t, GpuModel> models;
  uint64_t frame = 0;
  cv::Mat rgba;

  Impl(const geometry::CameraModel& cam, const RenderOptions& opts, std::shared_ptr<detail::EglContext> context)
      : camera(cam),
        options(checked(opts)),
        projector(cam, opts.max_half_fov_deg),
        egl(context ? std::move(context) : std::make_shared<detail::EglContext>()) {
    egl->make_current();
    drone_program.emplace("drone layer", source(detail::kDroneVertexShader, ""),
                          source(detail::kDroneFragmentShader, ""));
    glGenVertexArrays(1, &empty_vao);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    build_targets();
    build_noise();
    set_scene_uniforms();
    detail::check_gl("renderer set-up");
  }

  ~Impl() {
    try {
      egl->make_current();
    } catch (...) {
      return;  // the context is gone: so are its objects
    }
    for (auto& [id, m] : models) free_model(m);
    free_targets();
    glDeleteTextures(1, &noise_tex);
    glDeleteVertexArrays(1, &empty_vao);
    drone_program.reset();
    variants.clear();
  }

  static std::string source(const char* body, const std::string& defines) {
    return "#version 300 es\n" + defines + body;
  }

  // The program of one variant; `sensor`: with the lens and sensor functions (compose and sensor passes).
  const detail::GlProgram& variant(const std::string& name, const char* fragment, const std::string& defines,
                                   bool sensor = true) {
    auto& program = variants[name + "\n" + defines];
    if (!program) {
      std::string fragment_source = std::string("#version 300 es\n") + defines + detail::kFragmentPreamble;
      if (sensor) fragment_source += std::string(detail::kLensFunctions) + detail::kSensorFunctions;
      program = std::make_unique<detail::GlProgram>(name, source(detail::kFullscreenVertexShader, ""),
                                                    fragment_source + fragment);
    }
    return *program;
  }

  // The scene's random texture for value noise (256 x 256, repeating), from options.seed.
  void build_noise() {
    std::vector<uint8_t> values(256 * 256);
    uint64_t state = static_cast<uint64_t>(options.seed);
    for (uint8_t& v : values) v = static_cast<uint8_t>((state = splitmix64(state)) >> 56);
    if (noise_tex == 0) glGenTextures(1, &noise_tex);
    glBindTexture(GL_TEXTURE_2D, noise_tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, 256, 256, 0, GL_RED, GL_UNSIGNED_BYTE, values.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    noise_seed = options.seed;
  }

  static RenderOptions checked(const RenderOptions& options) {
    const std::vector<std::string> problems = options.validate();
    if (!problems.empty()) {
      std::string msg = "invalid render options: ";
      for (size_t i = 0; i < problems.size(); ++i) msg += (i ? "; " : "") + problems[i];
      throw std::invalid_argument(msg);
    }
    return options;
  }

  static GLuint texture(GLenum internal, GLenum format, GLenum type, int w, int h, GLenum filter, const void* data) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internal), w, h, 0, format, type, data);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
  }

  static void check_framebuffer(const char* what) {
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error(fmt::format("OpenGL: the {} framebuffer is incomplete (0x{:04x})", what, status));
    }
  }

  // The lens map, the pinhole layer that covers it, and the camera-sized targets.
  void build_targets() {
    const detail::LensMap lens = detail::compute_lens_map(camera, projector);
    if (lens.valid == 0) {
      throw std::runtime_error(fmt::format("camera {}: no pixel of the image is within {} degrees of the optical axis",
                                           camera.describe(), options.max_half_fov_deg));
    }
    GLint max_size = 0, max_rb = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    max_size = std::min(max_size, max_rb);
    // Layer density: supersampling times the camera's at its centre, reduced if the layer would be too large.
    fp = options.supersampling * std::max(camera.fx(), camera.fy());
    const Eigen::Vector2d extent = lens.max - lens.min;
    for (int attempt = 0; attempt < 8; ++attempt) {
      const double margin = 3.0 / fp;
      n0 = lens.min - Eigen::Vector2d::Constant(margin);
      layer_w = static_cast<int>(std::ceil((extent.x() + 2.0 * margin) * fp));
      layer_h = static_cast<int>(std::ceil((extent.y() + 2.0 * margin) * fp));
      const double shrink =
          std::min({1.0, static_cast<double>(max_size) / layer_w, static_cast<double>(max_size) / layer_h,
                    std::sqrt(kMaxLayerPixels / (static_cast<double>(layer_w) * layer_h))});
      if (shrink >= 1.0) break;
      fp *= shrink * 0.999;
    }

    const int cols = camera.width() + 1, rows = camera.height() + 1;
    std::vector<float> map(static_cast<size_t>(cols) * rows * 2);
    for (size_t k = 0; k < lens.corners.size(); ++k) {
      const Eigen::Vector2d& xy = lens.corners[k];
      const bool ok = xy.allFinite();
      map[2 * k] = ok ? static_cast<float>((xy.x() - n0.x()) * fp) : -1e9f;
      map[2 * k + 1] = ok ? static_cast<float>((xy.y() - n0.y()) * fp) : -1e9f;
    }
    map_tex = texture(GL_RG32F, GL_RG, GL_FLOAT, cols, rows, GL_NEAREST, map.data());
    // Pixel centres (the mean of the corners) where all four corners are in view.
    std::vector<float> centres(static_cast<size_t>(camera.width()) * camera.height() * 2);
    for (int j = 0; j < camera.height(); ++j) {
      for (int i = 0; i < camera.width(); ++i) {
        const size_t c[] = {static_cast<size_t>(j) * cols + i, static_cast<size_t>(j) * cols + i + 1,
                            static_cast<size_t>(j + 1) * cols + i, static_cast<size_t>(j + 1) * cols + i + 1};
        const bool in_view =
            map[2 * c[0]] > -1e8f && map[2 * c[1]] > -1e8f && map[2 * c[2]] > -1e8f && map[2 * c[3]] > -1e8f;
        const size_t k = 2 * (static_cast<size_t>(j) * camera.width() + i);
        for (int axis = 0; axis < 2; ++axis) {
          centres[k + axis] =
              in_view
                  ? 0.25f * (map[2 * c[0] + axis] + map[2 * c[1] + axis] + map[2 * c[2] + axis] + map[2 * c[3] + axis])
                  : -1e9f;
        }
      }
    }
    centres_tex = texture(GL_RG32F, GL_RG, GL_FLOAT, camera.width(), camera.height(), GL_NEAREST, centres.data());

    layer_colour = texture(GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT, layer_w, layer_h, GL_LINEAR, nullptr);
    layer_ids = texture(GL_R8UI, GL_RED_INTEGER, GL_UNSIGNED_BYTE, layer_w, layer_h, GL_NEAREST, nullptr);
    glGenRenderbuffers(1, &layer_depth);
    glBindRenderbuffer(GL_RENDERBUFFER, layer_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, layer_w, layer_h);
    glGenFramebuffers(1, &layer_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, layer_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, layer_colour, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, layer_ids, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, layer_depth);
    const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, both);
    check_framebuffer("drone layer");

    const int n = options.background_subsampling;
    bg_w = (camera.width() + n - 1) / n;
    bg_h = (camera.height() + n - 1) / n;
    bg_tex = texture(GL_RGBA16F, GL_RGBA, GL_HALF_FLOAT, bg_w, bg_h, GL_LINEAR, nullptr);
    glGenFramebuffers(1, &bg_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, bg_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, bg_tex, 0);
    check_framebuffer("background");

    accum_tex = texture(GL_RGBA32F, GL_RGBA, GL_FLOAT, camera.width(), camera.height(), GL_NEAREST, nullptr);
    glGenFramebuffers(1, &accum_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, accum_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, accum_tex, 0);
    check_framebuffer("accumulation");

    glGenRenderbuffers(1, &out_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, out_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, camera.width(), camera.height());
    glGenFramebuffers(1, &out_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, out_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, out_rb);
    check_framebuffer("output");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    rgba.create(camera.height(), camera.width(), CV_8UC4);
    detail::check_gl("render targets");
  }

  void free_targets() {
    glDeleteFramebuffers(1, &layer_fbo);
    glDeleteFramebuffers(1, &accum_fbo);
    glDeleteFramebuffers(1, &out_fbo);
    glDeleteFramebuffers(1, &bg_fbo);
    glDeleteRenderbuffers(1, &layer_depth);
    glDeleteRenderbuffers(1, &out_rb);
    const GLuint textures[] = {map_tex, centres_tex, layer_colour, layer_ids, accum_tex, bg_tex};
    glDeleteTextures(6, textures);
  }

  void set_scene_uniforms() {
    const RenderOptions& o = options;
    const double deg = M_PI / 180.0;
    const double el = o.sun_elevation_deg * deg, az = o.sun_azimuth_deg * deg;
    const Eigen::Vector3d sun_dir(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
    const double light = (o.ambient_intensity + o.sun_intensity * std::max(std::sin(el), 0.0)) / kDefaultLightLevel;
    const Eigen::Vector3d zenith = detail::linear_colour(o.sky_zenith_colour);
    const Eigen::Vector3d horizon = detail::linear_colour(o.sky_horizon_colour);
    const Eigen::Vector3d ground_a = detail::linear_colour(o.ground_colour_a);
    const Eigen::Vector3d ground_b = detail::linear_colour(o.ground_colour_b);
    const uint64_t seed_hash = splitmix64(static_cast<uint64_t>(o.seed));

    const bool scene = o.background == "scene";
    const bool blur = o.motion_blur_exposure_s > 0.0;
    const std::string noise = fmt::format("#define NOISE {}\n", o.noise_std > 0.0 || o.shot_noise > 0.0 ? 1 : 0);
    const std::string scene_defines =
        fmt::format("#define BG {}\n#define SCENE {}\n#define CLOUDS {}\n#define GROUND {}\n#define TREES {}\n",
                    o.background_subsampling, scene ? 1 : 0, scene && o.cloud_cover > 0.0 ? 1 : 0,
                    scene && o.ground ? 1 : 0, scene && o.treeline ? 1 : 0);
    const std::string compose_defines =
        fmt::format("#define SS {}\n#define FINAL {}\n", o.supersampling, blur ? 0 : 1) + noise;
    background_program = &variant("background", detail::kBackgroundFragmentShader, scene_defines, false);
    compose_program = &variant("compose", detail::kComposeFragmentShader, compose_defines + "#define LAYER 0\n");
    drones_program = &variant("compose drones", detail::kComposeFragmentShader, compose_defines + "#define LAYER 1\n");
    final_program = blur ? &variant("sensor", detail::kFinalFragmentShader, noise) : nullptr;
    const auto at = [](const detail::GlProgram& p, const char* name) { return glGetUniformLocation(p.id(), name); };

    const detail::GlProgram& r = *background_program;
    glUseProgram(r.id());
    glUniform1i(at(r, "u_map"), kMapUnit);
    glUniform1i(at(r, "u_noise"), kNoiseUnit);
    glUniform2i(at(r, "u_size"), camera.width(), camera.height());
    glUniform3f(at(r, "u_norm"), static_cast<float>(n0.x()), static_cast<float>(n0.y()), static_cast<float>(1.0 / fp));
    set3(at(r, "u_uniform_rgb"), detail::linear_colour(o.background_colour));
    set3(at(r, "u_zenith_rgb"), zenith);
    set3(at(r, "u_horizon_rgb"), horizon);
    set3(at(r, "u_sun_dir"), sun_dir);
    set3(at(r, "u_sun_glow_rgb"), o.sun_intensity * Eigen::Vector3d(1.0, 0.93, 0.8));
    set3(at(r, "u_cloud_rgb"), detail::linear_colour(o.cloud_colour) * std::min(light, 1.5));
    glUniform3f(at(r, "u_cloud"), static_cast<float>(o.cloud_cover), static_cast<float>(o.cloud_altitude_m),
                static_cast<float>(o.cloud_scale_m));
    set3(at(r, "u_ground_a_rgb"), ground_a * light);
    set3(at(r, "u_ground_b_rgb"), ground_b * light);
    glUniform1f(at(r, "u_ground_scale"), static_cast<float>(o.ground_texture_scale_m));
    set3(at(r, "u_tree_rgb"), detail::linear_colour(o.treeline_colour) * light);
    glUniform3f(at(r, "u_tree"), static_cast<float>(o.treeline_distance_m), static_cast<float>(o.treeline_height_m),
                static_cast<float>(o.treeline_depth_m));
    glUniform1f(at(r, "u_visibility"), static_cast<float>(o.visibility_m));
    glUniform2f(at(r, "u_offset"), static_cast<float>((seed_hash >> 32) % 1000),
                static_cast<float>((seed_hash >> 48) % 1000));

    glUseProgram(drone_program->id());
    const detail::GlProgram& d = *drone_program;
    glUniform1i(d.uniform("u_flat"), o.shading == "flat" ? 1 : 0);
    const Eigen::Vector3d sky_tint = unit_luma(0.65 * horizon + 0.35 * zenith);
    const Eigen::Vector3d ground_tint = unit_luma(0.5 * (ground_a + ground_b));
    set3(d.uniform("u_sun_rgb"), (el > 0.0 ? 1.5 * o.sun_intensity : 0.0) * Eigen::Vector3d(1.0, 0.96, 0.9));
    set3(d.uniform("u_sky_rgb"), o.ambient_intensity * sky_tint);
    set3(d.uniform("u_ground_rgb"),
         (0.3 * o.ambient_intensity + 0.25 * o.sun_intensity * std::max(std::sin(el), 0.0)) * ground_tint);
    const double n = kNearM, f = kFarM;
    glUniform2f(d.uniform("u_depth"), static_cast<float>((f + n) / (f - n)),
                static_cast<float>(-2.0 * f * n / (f - n)));
    glUniform4f(d.uniform("u_proj"), static_cast<float>(2.0 * fp / layer_w),
                static_cast<float>(-2.0 * fp * n0.x() / layer_w - 1.0), static_cast<float>(2.0 * fp / layer_h),
                static_cast<float>(-2.0 * fp * n0.y() / layer_h - 1.0));

    for (const detail::GlProgram* p : {compose_program, drones_program, final_program}) {
      if (p == nullptr) continue;
      glUseProgram(p->id());
      glUniform1i(at(*p, "u_map"), kMapUnit);
      glUniform1i(at(*p, "u_centres"), kCentresUnit);
      glUniform1i(at(*p, "u_layer"), kLayerUnit);
      glUniform1i(at(*p, "u_ids"), kIdsUnit);
      glUniform1i(at(*p, "u_accum"), kAccumUnit);
      glUniform1i(at(*p, "u_bg"), kBackgroundUnit);
      glUniform2f(at(*p, "u_layer_size"), static_cast<float>(layer_w), static_cast<float>(layer_h));
      glUniform2f(at(*p, "u_bg_scale"), static_cast<float>(1.0 / (o.background_subsampling * bg_w)),
                  static_cast<float>(1.0 / (o.background_subsampling * bg_h)));
      glUniform1f(at(*p, "u_noise_std"), static_cast<float>(o.noise_std));
      glUniform1f(at(*p, "u_shot"), static_cast<float>(o.shot_noise));
    }
    glUseProgram(0);
    sun_in_world = sun_dir;
  }

  const GpuModel& gpu_model(const DroneModel& model) {
    auto it = models.find(model.id());
    if (it == models.end()) {
      GpuModel m;
      std::vector<float> data;
      data.reserve(model.vertices().size() * 11);
      for (const DroneVertex& v : model.vertices()) {
        data.insert(data.end(), {v.p_in_body.x(), v.p_in_body.y(), v.p_in_body.z(), v.n_in_body.x(), v.n_in_body.y(),
                                 v.n_in_body.z(), v.colour.x(), v.colour.y(), v.colour.z(), v.colour.w(),
                                 static_cast<float>(v.part)});
      }
      glGenVertexArrays(1, &m.vao);
      glBindVertexArray(m.vao);
      glGenBuffers(1, &m.vbo);
      glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
      glGenBuffers(1, &m.ibo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ibo);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(model.indices().size() * sizeof(uint32_t)),
                   model.indices().data(), GL_STATIC_DRAW);
      const GLsizei stride = 11 * sizeof(float);
      const int sizes[] = {3, 3, 4, 1};
      size_t offset = 0;
      for (GLuint a = 0; a < 4; ++a) {
        glEnableVertexAttribArray(a);
        glVertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(offset));
        offset += sizes[a] * sizeof(float);
      }
      glBindVertexArray(0);
      m.opaque = static_cast<GLsizei>(model.opaque_index_count());
      m.total = static_cast<GLsizei>(model.indices().size());
      detail::check_gl("uploading a drone model");
      it = models.emplace(model.id(), m).first;
    }
    it->second.last_used = frame;
    return it->second;
  }

  static void free_model(GpuModel& m) {
    glDeleteBuffers(1, &m.vbo);
    glDeleteBuffers(1, &m.ibo);
    glDeleteVertexArrays(1, &m.vao);
  }

  // Layer pixels that a sphere (centre in the optical frame, radius) can cover; the whole layer when it reaches the
  // near plane.
  Rect sphere_rect(const Eigen::Vector3d& c, double r) const {
    if (c.z() - r <= kNearM) return {0, 0, layer_w, layer_h};
    const auto range = [&](double a, double z) {
      const double d = z * z - r * r;
      const double s = r * std::sqrt(a * a + d);
      return std::pair<double, double>((a * z - s) / d, (a * z + s) / d);
    };
    const auto [x0, x1] = range(c.x(), c.z());
    const auto [y0, y1] = range(c.y(), c.z());
    const auto to_px = [&](double v, double origin, int size, bool up) {
      const double p = (v - origin) * fp;
      const double clamped = std::clamp(up ? std::ceil(p) : std::floor(p), 0.0, static_cast<double>(size));
      return static_cast<int>(clamped);
    };
    return {to_px(x0, n0.x(), layer_w, false), to_px(y0, n0.y(), layer_h, false), to_px(x1, n0.x(), layer_w, true),
            to_px(y1, n0.y(), layer_h, true)};
  }

  // Draws the drones into the layer; returns the rectangle that was cleared (and drawn in).
  Rect draw_layer(const Eigen::Isometry3d& T_cam_to_world, std::vector<Posed>& posed) {
    Rect bounds{layer_w, layer_h, 0, 0};
    for (const Posed& p : posed) {
      const Rect r = sphere_rect(p.T_body_to_cam.translation(), p.model->bounding_radius());
      if (r.empty()) continue;
      bounds = {std::min(bounds.x0, r.x0), std::min(bounds.y0, r.y0), std::max(bounds.x1, r.x1),
                std::max(bounds.y1, r.y1)};
    }
    const Rect cleared = expanded(bounds, 2, layer_w, layer_h);
    if (cleared.empty()) return cleared;

    glBindFramebuffer(GL_FRAMEBUFFER, layer_fbo);
    glViewport(0, 0, layer_w, layer_h);
    glEnable(GL_SCISSOR_TEST);
    glScissor(cleared.x0, cleared.y0, cleared.x1 - cleared.x0, cleared.y1 - cleared.y0);
    const GLfloat transparent[] = {0.0f, 0.0f, 0.0f, 0.0f};
    const GLuint no_drone[] = {0u, 0u, 0u, 0u};
    glClearBufferfv(GL_COLOR, 0, transparent);
    glClearBufferuiv(GL_COLOR, 1, no_drone);
    const GLfloat far_depth = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);

    const detail::GlProgram& prog = *drone_program;
    glUseProgram(prog.id());
    const Eigen::Matrix3d R_world_to_cam = T_cam_to_world.linear().transpose();
    set3(prog.uniform("u_sun_cam"), R_world_to_cam * sun_in_world);
    set3(prog.uniform("u_up_cam"), R_world_to_cam * Eigen::Vector3d::UnitZ());
    const GLint parts_location = prog.uniform("u_cam_from_part[0]");
    const GLint id_location = prog.uniform("u_id");
    std::array<Eigen::Matrix4f, kMaxPropellers + 1> parts;
    const auto draw = [&](const Posed& p, bool translucent) {
      const GpuModel& m = gpu_model(*p.model);
      const GLsizei count = translucent ? m.total - m.opaque : m.opaque;
      if (count == 0) return;
      const size_t n = p.model->propellers().size() + 1;
      for (size_t k = 0; k < n; ++k) {
        parts[k] =
            (p.T_body_to_cam * p.model->part_transform(static_cast<int>(k), p.prop_angle_rad)).matrix().cast<float>();
      }
      glUniformMatrix4fv(parts_location, static_cast<GLsizei>(n), GL_FALSE, parts[0].data());
      glUniform1ui(id_location, static_cast<GLuint>(p.index + 1));
      glBindVertexArray(m.vao);
      const size_t first = translucent ? static_cast<size_t>(m.opaque) : 0;
      glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, reinterpret_cast<const void*>(first * sizeof(uint32_t)));
    };
    for (const Posed& p : posed) draw(p, false);
    // Translucent parts (propeller discs) last, far to near, without writing depth.
    std::sort(posed.begin(), posed.end(), [](const Posed& a, const Posed& b) {
      return a.T_body_to_cam.translation().norm() > b.T_body_to_cam.translation().norm();
    });
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    for (const Posed& p : posed) draw(p, true);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SCISSOR_TEST);
    glBindVertexArray(0);
    return cleared;
  }

  // Binds the textures every pass reads.
  void bind_textures() const {
    const std::pair<GLenum, GLuint> units[] = {
        {GL_TEXTURE0 + kMapUnit, map_tex},        {GL_TEXTURE0 + kLayerUnit, layer_colour},
        {GL_TEXTURE0 + kNoiseUnit, noise_tex},    {GL_TEXTURE0 + kIdsUnit, layer_ids},
        {GL_TEXTURE0 + kAccumUnit, accum_tex},    {GL_TEXTURE0 + kBackgroundUnit, bg_tex},
        {GL_TEXTURE0 + kCentresUnit, centres_tex}};
    for (const auto& [unit, texture] : units) {
      glActiveTexture(unit);
      glBindTexture(GL_TEXTURE_2D, texture);
    }
    glActiveTexture(GL_TEXTURE0);
  }

  // The sensor stage's per-frame uniforms: the id layer's valid rectangle, gain, noise seed.
  static void set_sensor(const detail::GlProgram& p, const Rect& cleared, double gain, uint64_t frame_seed) {
    const Rect ids = cleared.empty() ? Rect{1, 1, 0, 0} : cleared;
    glUniform4f(glGetUniformLocation(p.id(), "u_id_rect"), static_cast<float>(ids.x0), static_cast<float>(ids.y0),
                static_cast<float>(ids.x1), static_cast<float>(ids.y1));
    glUniform1f(glGetUniformLocation(p.id(), "u_gain"), static_cast<float>(gain));
    glUniform2ui(glGetUniformLocation(p.id(), "u_frame_seed"), static_cast<GLuint>(frame_seed & 0xffffffffu),
                 static_cast<GLuint>(frame_seed >> 32));
  }

  // Camera pixels whose lens-map points can fall in the layer rectangle `layer` (which must not be empty): the box
  // of the rectangle's outline (clamped to the field of view) projected through the lens, 2 px wider.
  Rect output_rect(const Rect& layer) const {
    if (layer.x0 == 0 && layer.y0 == 0 && layer.x1 == layer_w && layer.y1 == layer_h) {
      return {0, 0, camera.width(), camera.height()};
    }
    constexpr int kPerEdge = 64;
    double u0 = std::numeric_limits<double>::infinity(), v0 = u0, u1 = -u0, v1 = -u0;
    for (int e = 0; e < 4; ++e) {
      for (int k = 0; k <= kPerEdge; ++k) {
        const double f = static_cast<double>(k) / kPerEdge;
        const Eigen::Vector2d p = e == 0   ? Eigen::Vector2d(layer.x0 + f * (layer.x1 - layer.x0), layer.y0)
                                  : e == 1 ? Eigen::Vector2d(layer.x0 + f * (layer.x1 - layer.x0), layer.y1)
                                  : e == 2 ? Eigen::Vector2d(layer.x0, layer.y0 + f * (layer.y1 - layer.y0))
                                           : Eigen::Vector2d(layer.x1, layer.y0 + f * (layer.y1 - layer.y0));
        Eigen::Vector2d n = n0 + p / fp;
        const double r = n.norm(), r_max = projector.max_normalized_radius(n);
        if (r > r_max) n *= r_max / r;
        const Eigen::Vector2d uv = camera.project(Eigen::Vector3d(n.x(), n.y(), 1.0));
        u0 = std::min(u0, uv.x());
        u1 = std::max(u1, uv.x());
        v0 = std::min(v0, uv.y());
        v1 = std::max(v1, uv.y());
      }
    }
    const auto clamp_to = [](double v, int size) {
      return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(size)));
    };
    return {clamp_to(std::floor(u0) - 2.0, camera.width()), clamp_to(std::floor(v0) - 2.0, camera.height()),
            clamp_to(std::ceil(u1) + 3.0, camera.width()), clamp_to(std::ceil(v1) + 3.0, camera.height())};
  }

  // The background pass, then the background and the drone layer over it through the lens: into the output through
  // the sensor stage (no motion blur), or added with `weight` to the accumulation target.
  // `background_weight` < 0: the background of the previous call stands (a still camera during motion blur), only
  // what the drones change is added.
  void remap(const Eigen::Isometry3d& T_cam_to_world, const Rect& cleared, float weight, float background_weight,
             bool to_output, double gain, uint64_t frame_seed) {
    bind_textures();
    glBindVertexArray(empty_vao);
    const bool background = background_weight >= 0.0f;
    if (background) {
      const Eigen::Matrix3f R = T_cam_to_world.linear().cast<float>();
      glBindFramebuffer(GL_FRAMEBUFFER, bg_fbo);
      glViewport(0, 0, bg_w, bg_h);
      glUseProgram(background_program->id());
      // Absent from the uniform-background variant.
      glUniformMatrix3fv(glGetUniformLocation(background_program->id(), "u_R_cam_to_world"), 1, GL_FALSE, R.data());
      set3(glGetUniformLocation(background_program->id(), "u_cam_in_world"), T_cam_to_world.translation());
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }

    glBindFramebuffer(GL_FRAMEBUFFER, to_output ? out_fbo : accum_fbo);
    glViewport(0, 0, camera.width(), camera.height());
    if (!to_output) {
      glEnable(GL_BLEND);
      glBlendFunc(GL_ONE, GL_ONE);
    }
    for (const detail::GlProgram* program : {compose_program, drones_program}) {
      const detail::GlProgram& r = *program;
      if (&r == compose_program && !background) continue;
      if (&r == drones_program) {  // only where the drones are
        if (cleared.empty()) break;
        const Rect out = output_rect(cleared);
        if (out.empty()) break;
        glEnable(GL_SCISSOR_TEST);
        glScissor(out.x0, out.y0, out.x1 - out.x0, out.y1 - out.y0);
      }
      glUseProgram(r.id());
      // Sample only inside what was cleared, one pixel in (bilinear filtering reads a neighbour).
      const Rect inside = cleared.empty() ? Rect{1, 1, 0, 0} : expanded(cleared, -1, layer_w, layer_h);
      glUniform4f(glGetUniformLocation(r.id(), "u_rect"), static_cast<float>(inside.x0), static_cast<float>(inside.y0),
                  static_cast<float>(inside.x1), static_cast<float>(inside.y1));
      glUniform1f(glGetUniformLocation(r.id(), "u_weight"), &r == compose_program ? background_weight : weight);
      if (to_output) set_sensor(r, cleared, gain, frame_seed);
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_BLEND);
  }

  // The sensor stage on the accumulated motion-blur samples.
  void sensor_pass(const Rect& cleared, double gain, uint64_t frame_seed) {
    glBindFramebuffer(GL_FRAMEBUFFER, out_fbo);
    glViewport(0, 0, camera.width(), camera.height());
    glUseProgram(final_program->id());
    set_sensor(*final_program, cleared, gain, frame_seed);
    bind_textures();
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }

  double frame_gain(int64_t utime, uint64_t frame_seed) const {
    double gain = options.exposure_gain;
    if (options.exposure_drift_amplitude > 0.0) {
      gain *= 1.0 + options.exposure_drift_amplitude *
                        std::sin(2.0 * M_PI * (static_cast<double>(utime) * 1e-6) / options.exposure_drift_period_s);
    }
    if (options.exposure_jitter > 0.0) {
      gain *= std::exp(options.exposure_jitter * normal_from_seed(frame_seed ^ 0x5eed0fe4a11c0deull));
    }
    return gain;
  }

  std::vector<Posed> pose_drones(const std::vector<DroneInstance>& drones, const Eigen::Isometry3d& T_cam_to_world,
                                 double t) const {
    const Eigen::Isometry3d T_world_to_cam = T_cam_to_world.inverse();
    std::vector<Posed> posed;
    posed.reserve(drones.size());
    for (size_t i = 0; i < drones.size(); ++i) {
      const DroneInstance& d = drones[i];
      const Eigen::Isometry3d T_body = advance(d.T_body_to_world, d.v_body_in_world, d.w_body_in_body, t);
      posed.push_back(Posed{i, d.model, T_world_to_cam * T_body, d.prop_angle_rad + d.prop_rate_rad_s * t});
    }
    return posed;
  }

  RenderResult render(const Eigen::Isometry3d& T_cam_to_world, const std::vector<DroneInstance>& drones, int64_t utime,
                      uint64_t frame_seed, const CameraMotion& motion) {
    if (drones.size() > 254) {
      throw std::invalid_argument(fmt::format("Renderer::render: {} drones, at most 254 per frame", drones.size()));
    }
    for (size_t i = 0; i < drones.size(); ++i) {
      if (drones[i].model == nullptr) {
        throw std::invalid_argument(
            fmt::format("Renderer::render: drones[{}] (vehicle {}) has no model", i, drones[i].vehicle_id));
      }
    }
    egl->make_current();
    ++frame;
    const bool blur = options.motion_blur_exposure_s > 0.0;
    const int samples = blur ? options.motion_blur_samples : 1;

    RenderResult result;
    result.exposure_gain = frame_gain(utime, frame_seed);
    Rect cleared;
    if (!blur) {
      std::vector<Posed> posed = pose_drones(drones, T_cam_to_world, 0.0);
      cleared = draw_layer(T_cam_to_world, posed);
      remap(T_cam_to_world, cleared, 1.0f, 1.0f, true, result.exposure_gain, frame_seed);
    } else {
      glBindFramebuffer(GL_FRAMEBUFFER, accum_fbo);
      const GLfloat zero[] = {0.0f, 0.0f, 0.0f, 0.0f};
      glClearBufferfv(GL_COLOR, 0, zero);
      // A still camera sees the same background all exposure long: it is drawn once, with the full weight.
      const bool still = motion.v_cam_in_world.isZero(0.0) && motion.w_cam_in_cam.isZero(0.0);
      const float weight = 1.0f / static_cast<float>(samples);
      for (int k = 0; k < samples; ++k) {
        const double t = ((k + 0.5) / samples - 0.5) * options.motion_blur_exposure_s;
        const Eigen::Isometry3d T_cam_t = advance(T_cam_to_world, motion.v_cam_in_world, motion.w_cam_in_cam, t);
        std::vector<Posed> posed = pose_drones(drones, T_cam_t, t);
        cleared = draw_layer(T_cam_t, posed);
        const float background_weight = !still ? weight : k == 0 ? 1.0f : -1.0f;
        remap(T_cam_t, cleared, weight, background_weight, false, 1.0, 0);
      }
      // The mask is taken at the middle of the exposure.
      std::vector<Posed> posed = pose_drones(drones, T_cam_to_world, 0.0);
      cleared = draw_layer(T_cam_to_world, posed);
      sensor_pass(cleared, result.exposure_gain, frame_seed);
    }
    glReadPixels(0, 0, camera.width(), camera.height(), GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    detail::check_gl("rendering a frame");

    result.bgr.create(camera.height(), camera.width(), CV_8UC3);
    result.mask.create(camera.height(), camera.width(), CV_8UC1);
    cv::Mat outputs[] = {result.bgr, result.mask};
    const int from_to[] = {2, 0, 1, 1, 0, 2, 3, 3};
    cv::mixChannels(&rgba, 1, outputs, 2, from_to, 4);

    std::vector<int> counts(drones.size() + 1, 0);
    for (int y = 0; y < result.mask.rows; ++y) {
      const uint8_t* row = result.mask.ptr<uint8_t>(y);
      for (int x = 0; x < result.mask.cols; ++x) {
        if (row[x] != 0 && row[x] <= drones.size()) ++counts[row[x]];
      }
    }
    result.boxes.reserve(drones.size());
    for (size_t i = 0; i < drones.size(); ++i) {
      const DroneInstance& d = drones[i];
      RenderedBox box = projector.project(*d.model, T_cam_to_world, d.T_body_to_world, d.prop_angle_rad, d.vehicle_id);
      box.visible_pixels = counts[i + 1];
      box.visible = box.visible && box.visible_pixels > 0;
      result.boxes.push_back(box);
    }

    for (auto it = models.begin(); it != models.end();) {  // free the GPU copies of models no longer drawn
      if (frame - it->second.last_used > kEvictAfterFrames) {
        free_model(it->second);
        it = models.erase(it);
      } else {
        ++it;
      }
    }
    return result;
  }

  void set_options(const RenderOptions& next) {
    const RenderOptions valid = checked(next);
    egl->make_current();
    const bool rebuild = valid.supersampling != options.supersampling ||
                         valid.max_half_fov_deg != options.max_half_fov_deg ||
                         valid.background_subsampling != options.background_subsampling;
    options = valid;
    if (rebuild) {
      projector = TruthBoxProjector(camera, options.max_half_fov_deg);
      free_targets();
      build_targets();
    }
    if (options.seed != noise_seed) build_noise();
    set_scene_uniforms();
    detail::check_gl("changing the render options");
  }
};

Renderer::Renderer(const geometry::CameraModel& camera, const RenderOptions& options)
    : impl_(std::make_unique<Impl>(camera, options, nullptr)) {}
Renderer::Renderer(const geometry::CameraModel& camera, const RenderOptions& options, const Renderer& share_context)
    : impl_(std::make_unique<Impl>(camera, options, share_context.impl_->egl)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

RenderResult Renderer::render(const Eigen::Isometry3d& T_cam_to_world, const std::vector<DroneInstance>& drones,
                              int64_t utime, uint64_t frame_seed, const CameraMotion& camera_motion) {
  return impl_->render(T_cam_to_world, drones, utime, frame_seed, camera_motion);
}

void Renderer::set_options(const RenderOptions& options) { impl_->set_options(options); }
const geometry::CameraModel& Renderer::camera() const { return impl_->camera; }
const RenderOptions& Renderer::options() const { return impl_->options; }
std::string Renderer::gl_renderer() const { return impl_->egl->renderer(); }
cv::Size Renderer::pinhole_size() const { return {impl_->layer_w, impl_->layer_h}; }

}  // namespace wingman::sim
