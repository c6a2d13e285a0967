// SPDX-License-Identifier: MIT
// `wingman dataset synth`: rendered, labelled training images with domain randomization, in the YOLO layout.
#include "wingman/tools/dataset_synth.hpp"

#include "wingman/tools/dataset_from_log.hpp"

#include "run_verb.hpp"
#include "synth_random.hpp"
#include "verb_layers.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/detection_class.hpp>
#include <wingman/common/json.hpp>
#include <wingman/common/progress.hpp>
#include <wingman/geometry/camera_model.hpp>
#include <wingman/geometry/sphere_projection.hpp>
#include <wingman/sim/distractor_model.hpp>
#include <wingman/sim/drone_model.hpp>
#include <wingman/sim/renderer.hpp>
#include <wingman/sim/truth_box.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;
constexpr int kMaxPlacements = 50;  // attempts to place a visible target in one image

using Random = SynthRandom;

// Random streams: one per purpose, so that adding a draw in one place leaves the others alone.
enum SynthStream : uint64_t {
  kCameraStream = 1,
  kImageStream = 2,
  kNegativeStream = 3,    // per image: whether it is a negative
  kDistractorStream = 4,  // per placement attempt: the distractors
};

using Colour = std::vector<double>;

Colour pick(Random& rng, const std::vector<Colour>& palette, double jitter = 0.12) {
  Colour c = palette[rng.index(palette.size())];
  for (double& v : c) v = std::clamp(v * rng.uniform(1.0 - jitter, 1.0 + jitter), 0.0, 1.0);
  return c;
}

const std::vector<Colour> kZenith = {{0.25, 0.45, 0.8}, {0.2, 0.4, 0.85},  {0.15, 0.3, 0.7},
                                     {0.45, 0.55, 0.7}, {0.6, 0.62, 0.66}, {0.5, 0.48, 0.62}};
const std::vector<Colour> kHorizon = {
    {0.75, 0.82, 0.9}, {0.85, 0.86, 0.88}, {0.7, 0.75, 0.8}, {0.9, 0.78, 0.62}, {0.8, 0.8, 0.78}};
const std::vector<Colour> kGround = {{0.3, 0.42, 0.18}, {0.45, 0.4, 0.28}, {0.55, 0.5, 0.3}, {0.2, 0.3, 0.12},
                                     {0.76, 0.7, 0.5},  {0.9, 0.9, 0.92},  {0.4, 0.4, 0.42}, {0.35, 0.3, 0.22}};
const std::vector<Colour> kTrees = {{0.12, 0.2, 0.1}, {0.2, 0.25, 0.12}, {0.3, 0.24, 0.14}, {0.1, 0.15, 0.12}};
const std::vector<Colour> kAirframe = {{0.05, 0.05, 0.05}, {0.15, 0.15, 0.15}, {0.4, 0.4, 0.42},  {0.92, 0.92, 0.92},
                                       {0.8, 0.1, 0.1},    {0.1, 0.25, 0.8},   {0.95, 0.5, 0.05}, {0.9, 0.8, 0.1},
                                       {0.1, 0.5, 0.2},    {0.03, 0.74, 1.0}};

// A random calibrated camera: field of view, principal point, and a radtan or equidistant lens.
geometry::CameraModel random_camera(const DatasetSynthConfig& c, Random& rng, int k) {
  const double half_fov = 0.5 * rng.uniform(c.hfov_min_deg, c.hfov_max_deg) * kSynthDeg;
  const double cx = 0.5 * c.width - 0.5 + rng.normal() * 0.01 * c.width;
  const double cy = 0.5 * c.height - 0.5 + rng.normal() * 0.01 * c.height;
  const double aspect = 1.0 + 0.003 * rng.normal();
  const std::string name = fmt::format("synth_camera_{}", k);
  if (rng.chance(c.fisheye_fraction)) {
    const double f = 0.5 * c.width / half_fov;  // equidistant: r = f theta at the image edge
    return geometry::CameraModel(
        c.width, c.height, f, f * aspect, cx, cy, geometry::Distortion::kEquidistant,
        {rng.uniform(-0.04, 0.04), rng.uniform(-0.01, 0.01), rng.uniform(-0.003, 0.003), rng.uniform(-0.001, 0.001)},
        name);
  }
  const double k1 = rng.uniform(c.radtan_k1_min, c.radtan_k1_max);
  // Focal length from the field of view of the distorted image edge: r_d = r (1 + k1 r^2 + k2 r^4).
  const double r = std::tan(half_fov), k2 = -0.3 * k1 + rng.uniform(-0.02, 0.02);
  const double f = 0.5 * c.width / (r * std::max(0.3, 1.0 + k1 * r * r + k2 * r * r * r * r));
  return geometry::CameraModel(c.width, c.height, f, f * aspect, cx, cy, geometry::Distortion::kRadTan,
                               {k1, k2, rng.uniform(-0.002, 0.002), rng.uniform(-0.002, 0.002), 0.0}, name);
}

}  // namespace

// The scene, light and sensor of one image, around the configured base.
sim::RenderOptions random_scene(const DatasetSynthConfig& c, SynthRandom& rng) {
  sim::RenderOptions o = c.render;
  o.seed = static_cast<int64_t>(rng.next() >> 1);
  o.sky_zenith_colour = pick(rng, kZenith);
  o.sky_horizon_colour = pick(rng, kHorizon);
  o.cloud_cover = rng.chance(0.2) ? 0.0 : rng.uniform(0.05, 0.9);
  o.cloud_scale_m = rng.log_uniform(300.0, 2000.0);
  o.sun_azimuth_deg = rng.uniform(0.0, 360.0);
  o.sun_elevation_deg = rng.uniform(5.0, 75.0);
  o.sun_intensity = rng.chance(0.15) ? rng.uniform(0.0, 0.3) : rng.uniform(0.6, 1.4);  // overcast sometimes
  o.ambient_intensity = rng.uniform(0.3, 0.7);
  o.ground_colour_a = pick(rng, kGround);
  o.ground_colour_b = pick(rng, kGround);
  o.ground_texture_scale_m = rng.log_uniform(10.0, 100.0);
  o.treeline = rng.chance(0.8);
  o.treeline_distance_m = rng.uniform(120.0, 900.0);
  o.treeline_height_m = rng.uniform(6.0, 30.0);
  o.treeline_depth_m = rng.uniform(30.0, 400.0);
  o.treeline_colour = pick(rng, kTrees);
  o.visibility_m = rng.log_uniform(2000.0, 25000.0);
  o.exposure_gain = c.render.exposure_gain * std::exp(c.exposure_jitter * rng.normal());
  o.exposure_jitter = 0.0;
  o.noise_std = rng.uniform(0.0, c.noise_std_max);
  o.shot_noise = rng.uniform(0.0, c.shot_noise_max);
  o.motion_blur_exposure_s = rng.chance(c.blur_fraction) ? rng.uniform(0.002, c.blur_exposure_max_s) : 0.0;
  o.motion_blur_samples = 5;
  return o;
}

// A random procedural multirotor: frame, size, colours, propellers, landing gear.
sim::DroneSpec random_airframe(const DatasetSynthConfig& c, SynthRandom& rng, const std::string& frame) {
  sim::DroneSpec s;
  const double u = rng.uniform();  // drawn even when `frame` is given, so that the other draws stay the same
  s.frame = !frame.empty() ? frame : u < 0.6 ? "quad" : u < 0.85 ? "hex" : "octo";
  const int n = s.arm_count();
  const double scale = rng.log_uniform(c.scale_min, c.scale_max);
  s.arm_length_m = 0.23 * scale * std::sqrt(n / 4.0) * rng.uniform(0.9, 1.1);
  s.arm_width_m = 0.022 * scale * rng.uniform(0.7, 1.3);
  s.body_size_m = 0.14 * scale * std::sqrt(n / 4.0) * rng.uniform(0.8, 1.3);
  s.body_height_m = 0.06 * scale * rng.uniform(0.7, 1.4);
  s.motor_radius_m = 0.014 * scale * rng.uniform(0.8, 1.3);
  s.motor_height_m = 0.03 * scale * rng.uniform(0.7, 1.3);
  const double max_prop = 2.0 * s.arm_length_m * std::sin(kSynthPi / n) * 0.97;  // neighbouring props do not overlap
  s.prop_diameter_m = std::min(0.2295 * scale * rng.uniform(0.8, 1.15), max_prop);
  s.prop_chord_m = std::min(0.02 * scale * rng.uniform(0.8, 1.4), 0.4 * s.prop_diameter_m);
  s.prop_blades = rng.chance(0.7) ? 2 : rng.chance(0.8) ? 3 : 4;
  s.prop_style = rng.chance(c.disc_fraction) ? "disc" : "blades";
  s.prop_disc_alpha = rng.uniform(0.2, 0.6);
  s.gear_height_m = rng.chance(0.7) ? 0.12 * scale * rng.uniform(0.5, 1.5) : 0.0;
  s.gear_width_m = 0.2 * scale * rng.uniform(0.8, 1.3);
  s.gear_length_m = 0.18 * scale * rng.uniform(0.8, 1.3);
  s.gear_tube_m = 0.008 * scale * rng.uniform(0.8, 1.5);
  s.motor_radius_m = std::min(s.motor_radius_m, 0.45 * s.arm_length_m);
  s.body_colour = pick(rng, kAirframe);
  s.front_arm_colour = pick(rng, kAirframe);
  s.rear_arm_colour = rng.chance(0.5) ? s.front_arm_colour : pick(rng, kAirframe);
  s.motor_colour = pick(rng, kAirframe);
  s.prop_colour = pick(rng, kAirframe);
  s.gear_colour = pick(rng, kAirframe);
  return s;
}

namespace {

Eigen::Matrix3d rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// A camera pose: height above the ground, heading, pitch (up > 0) and roll; optical frame x right, y down, z forward.
Eigen::Isometry3d random_camera_pose(const DatasetSynthConfig& c, Random& rng) {
  Eigen::Matrix3d R_forward_to_optical;  // columns: optical x, y, z in the forward frame (x fwd, y left, z up)
  R_forward_to_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const double yaw = rng.uniform(-kSynthPi, kSynthPi);
  const double pitch = rng.uniform(c.camera_pitch_min_deg, c.camera_pitch_max_deg) * kSynthDeg;
  const double roll = rng.uniform(-c.camera_roll_max_deg, c.camera_roll_max_deg) * kSynthDeg;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rpy(roll, -pitch, yaw) * R_forward_to_optical;  // pitching up turns x (forward) towards +z
  T.translation() = Eigen::Vector3d(rng.uniform(-500.0, 500.0), rng.uniform(-500.0, 500.0),
                                    rng.uniform(c.camera_height_min_m, c.camera_height_max_m));
  return T;
}

const std::vector<Colour> kAircraft = {{0.92, 0.92, 0.93}, {0.85, 0.86, 0.88}, {0.7, 0.72, 0.75},
                                       {0.95, 0.95, 0.9},  {0.3, 0.32, 0.35},  {0.8, 0.12, 0.1}};
const std::vector<Colour> kBirdColours = {{0.05, 0.05, 0.05}, {0.15, 0.13, 0.12}, {0.35, 0.28, 0.2},
                                          {0.5, 0.5, 0.5},    {0.9, 0.9, 0.9},    {0.55, 0.45, 0.3}};
const std::vector<Colour> kHelicopter = {{0.92, 0.92, 0.92}, {0.8, 0.1, 0.1}, {0.9, 0.8, 0.1},  {0.1, 0.25, 0.6},
                                         {0.2, 0.25, 0.15},  {0.1, 0.1, 0.1}, {0.95, 0.5, 0.05}};
constexpr double kDistractorMaxRangeM = 4000.0;  // the renderer clips at 5 km

/// A distractor's shape: its kind's span, proportions and colours.
sim::DistractorSpec random_distractor(Random& rng) {
  sim::DistractorSpec s;
  s.kind = static_cast<sim::DistractorKind>(1 + static_cast<int>(rng.index(3)));
  switch (s.kind) {
    case sim::DistractorKind::kAirplane:
      s.span_m = rng.log_uniform(9.0, 60.0);
      s.length_ratio = rng.uniform(0.75, 1.1);
      s.wing_angle_deg = rng.uniform(0.0, 7.0);  // dihedral
      s.colour = pick(rng, kAircraft);
      s.accent_colour = rng.chance(0.6) ? s.colour : pick(rng, kAircraft);
      break;
    case sim::DistractorKind::kBird:
      s.span_m = rng.log_uniform(0.25, 1.8);
      s.length_ratio = rng.uniform(0.3, 0.55);
      s.wing_angle_deg = rng.uniform(-45.0, 60.0);  // the wing beat at the exposure
      s.colour = pick(rng, kBirdColours);
      s.accent_colour = rng.chance(0.5) ? s.colour : pick(rng, kBirdColours);
      break;
    case sim::DistractorKind::kHelicopter:
      s.span_m = rng.log_uniform(8.0, 16.0);
      s.length_ratio = rng.uniform(0.95, 1.2);
      s.colour = pick(rng, kHelicopter);
      s.accent_colour = pick(rng, {{0.1, 0.1, 0.1}, {0.3, 0.3, 0.3}, {0.6, 0.6, 0.6}});
      break;
  }
  return s;
}

/// One distractor of an image.
struct Distractor {
  sim::DistractorSpec spec;
  std::shared_ptr<const sim::DroneModel> model;
  sim::DroneInstance instance;
};

/// Up to `count` distractors seen by `camera` from `T_cam_to_world`, each at a random pixel with a random apparent
/// span in pixels, above the ground, nearer than kDistractorMaxRangeM; a distractor that cannot be placed in 20 draws
/// is left out.
std::vector<Distractor> place_distractors(const DatasetSynthConfig& c, const geometry::CameraModel& camera,
                                          const sim::TruthBoxProjector& fov, const Eigen::Isometry3d& T_cam_to_world,
                                          size_t count, Random& rng) {
  std::vector<Distractor> out;
  for (size_t k = 0; k < count; ++k) {
    Distractor d;
    d.spec = random_distractor(rng);
    d.model = std::make_shared<const sim::DroneModel>(sim::distractor_model(d.spec));
    const double radius = d.model->bounding_radius();
    bool placed = false;
    for (int attempt = 0; attempt < 20 && !placed; ++attempt) {
      const Eigen::Vector2d uv(rng.uniform(-0.5, c.width - 0.5), rng.uniform(-0.5, c.height - 0.5));
      const double px = rng.log_uniform(c.distractor_px_min, c.distractor_px_max);
      const double range = d.spec.span_m * camera.fx() / px;
      const Eigen::Vector3d ray = camera.unproject(uv);
      if (!ray.allFinite() || !fov.in_field_of_view(ray) || range + radius > kDistractorMaxRangeM) continue;
      const Eigen::Vector3d p_in_world = T_cam_to_world * (ray.normalized() * range);
      if (p_in_world.z() < radius + 0.3) continue;  // under the ground
      d.instance.T_body_to_world.translation() = p_in_world;
      placed = true;
    }
    if (!placed) continue;
    // Level flight, banking and pitching a little; velocity along the body's nose (motion blur).
    const double yaw = rng.uniform(-kSynthPi, kSynthPi);
    const double roll = rng.uniform(-35.0, 35.0) * kSynthDeg, pitch = rng.uniform(-10.0, 10.0) * kSynthDeg;
    d.instance.T_body_to_world.linear() =
        (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    const double speed = d.spec.kind == sim::DistractorKind::kAirplane ? rng.uniform(40.0, 150.0)
                         : d.spec.kind == sim::DistractorKind::kBird   ? rng.uniform(5.0, 15.0)
                                                                       : rng.uniform(0.0, 50.0);
    d.instance.v_body_in_world = d.instance.T_body_to_world.linear().col(0) * speed;
    d.instance.prop_angle_rad = rng.uniform(0.0, 2.0 * kSynthPi);
    d.instance.prop_rate_rad_s = d.spec.kind == sim::DistractorKind::kHelicopter ? rng.uniform(25.0, 45.0) : 0.0;
    out.push_back(std::move(d));
  }
  return out;
}

common::Json vec_json(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

/// A rendered box in the metadata: centre and size in pixels, truncated, visible pixels.
common::Json box_json(const sim::RenderedBox& b) {
  return {{"cx", b.cx},
          {"cy", b.cy},
          {"w", b.w},
          {"h", b.h},
          {"truncated", b.truncated},
          {"visible_pixels", b.visible_pixels}};
}

common::Json quat_json(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return {q.w(), q.x(), q.y(), q.z()};
}

// A DroneSpec as one JSON object (the keys of DroneSpec::visit without a prefix).
class JsonSpecWriter {
 public:
  template <class T>
  void operator()(const std::string& key, const T& value, const char* /*doc*/) {
    json_[key] = value;
  }
  common::Json json() const { return json_; }

 private:
  common::Json json_ = common::Json::object();
};

common::Json spec_json(const sim::DroneSpec& spec) {
  JsonSpecWriter writer;
  const_cast<sim::DroneSpec&>(spec).visit(writer, "");  // visit() only reads through a writer
  return writer.json();
}

std::vector<std::string> mesh_files(const std::vector<std::string>& args) {
  static const std::vector<std::string> kExtensions = {".glb", ".gltf", ".obj", ".dae", ".stl", ".ply", ".fbx"};
  std::vector<std::string> files;
  for (const std::string& arg : args) {
    if (fs::is_directory(arg)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::directory_iterator(arg)) {
        std::string ext = entry.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
        if (entry.is_regular_file() && std::find(kExtensions.begin(), kExtensions.end(), ext) != kExtensions.end()) {
          found.push_back(entry.path().string());
        }
      }
      if (found.empty())
        throw std::runtime_error(fmt::format("--meshes {}: no mesh files (.glb .gltf .obj .dae .stl .ply .fbx)", arg));
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(arg)) {
      files.push_back(arg);
    } else {
      throw std::runtime_error(fmt::format("--meshes {}: no such file or folder", arg));
    }
  }
  return files;
}

// One camera of the pool.
struct Camera {
  geometry::CameraModel model;
  std::unique_ptr<sim::Renderer> renderer;
  sim::TruthBoxProjector field_of_view;
};

}  // namespace

std::vector<std::string> DatasetSynthConfig::validate() const {
  using common::problem;
  std::vector<std::string> p = render.validate();
  const auto range = [&](const char* lo_key, double lo, const char* hi_key, double hi, double min, double max) {
    if (!(lo >= min && lo <= max)) p.push_back(problem(lo_key, lo, fmt::format("must be in [{}, {}]", min, max)));
    if (!(hi >= min && hi <= max)) p.push_back(problem(hi_key, hi, fmt::format("must be in [{}, {}]", min, max)));
    if (lo > hi) p.push_back(problem(hi_key, hi, fmt::format("must be >= {} ({})", lo_key, lo)));
  };
  const auto fraction = [&](const char* key, double v) {
    if (!(v >= 0.0 && v <= 1.0)) p.push_back(problem(key, v, "must be in [0, 1]"));
  };
  if (width < 32 || width > 8192) p.push_back(problem("synth.width", width, "must be in 32..8192"));
  if (height < 32 || height > 8192) p.push_back(problem("synth.height", height, "must be in 32..8192"));
  if (cameras < 1 || cameras > 64) p.push_back(problem("synth.cameras", cameras, "must be in 1..64"));
  range("synth.hfov_min_deg", hfov_min_deg, "synth.hfov_max_deg", hfov_max_deg, 10.0, 160.0);
  range("synth.radtan_k1_min", radtan_k1_min, "synth.radtan_k1_max", radtan_k1_max, -0.6, 0.6);
  range("synth.range_min_m", range_min_m, "synth.range_max_m", range_max_m, 0.3, 2000.0);
  range("synth.scale_min", scale_min, "synth.scale_max", scale_max, 0.1, 10.0);
  range("synth.camera_height_min_m", camera_height_min_m, "synth.camera_height_max_m", camera_height_max_m, 0.1,
        10000.0);
  range("synth.camera_pitch_min_deg", camera_pitch_min_deg, "synth.camera_pitch_max_deg", camera_pitch_max_deg, -90.0,
        90.0);
  if (!(camera_roll_max_deg >= 0.0 && camera_roll_max_deg <= 180.0)) {
    p.push_back(problem("synth.camera_roll_max_deg", camera_roll_max_deg, "must be in [0, 180]"));
  }
  if (!(target_tilt_max_deg >= 0.0 && target_tilt_max_deg <= 90.0)) {
    p.push_back(problem("synth.target_tilt_max_deg", target_tilt_max_deg, "must be in [0, 90]"));
  }
  fraction("synth.fisheye_fraction", fisheye_fraction);
  fraction("synth.mesh_fraction", mesh_fraction);
  fraction("synth.disc_fraction", disc_fraction);
  fraction("synth.blur_fraction", blur_fraction);
  fraction("synth.val_fraction", val_fraction);
  fraction("synth.horizon_fraction", horizon_fraction);
  if (!(horizon_elevation_max_deg >= 0.0 && horizon_elevation_max_deg <= 45.0)) {
    p.push_back(problem("synth.horizon_elevation_max_deg", horizon_elevation_max_deg, "must be in [0, 45] degrees"));
  }
  if (!(blur_exposure_max_s >= 0.002 && blur_exposure_max_s <= 0.1)) {
    p.push_back(problem("synth.blur_exposure_max_s", blur_exposure_max_s, "must be in [0.002, 0.1]"));
  }
  if (!(noise_std_max >= 0.0 && noise_std_max <= 50.0)) {
    p.push_back(problem("synth.noise_std_max", noise_std_max, "must be in [0, 50]"));
  }
  if (!(shot_noise_max >= 0.0 && shot_noise_max <= 50.0)) {
    p.push_back(problem("synth.shot_noise_max", shot_noise_max, "must be in [0, 50]"));
  }
  if (!(exposure_jitter >= 0.0 && exposure_jitter <= 2.0)) {
    p.push_back(problem("synth.exposure_jitter", exposure_jitter, "must be in [0, 2]"));
  }
  if (image_format != "png" && image_format != "jpg") {
    p.push_back(problem("synth.image_format", image_format, "must be png or jpg"));
  }
  if (jpeg_quality < 1 || jpeg_quality > 100)
    p.push_back(problem("synth.jpeg_quality", jpeg_quality, "must be in 1..100"));
  if (min_visible_pixels < 1) p.push_back(problem("synth.min_visible_pixels", min_visible_pixels, "must be >= 1"));
  if (distractors_max < 0 || distractors_max > 16)
    p.push_back(problem("synth.distractors_max", distractors_max, "must be in 0..16"));
  range("synth.distractor_px_min", distractor_px_min, "synth.distractor_px_max", distractor_px_max, 1.0, 2000.0);
  fraction("synth.negative_fraction", negative_fraction);
  if (negative_fraction > 0.0 && distractors_max < 1)
    p.push_back(problem("synth.negative_fraction", negative_fraction,
                        "needs synth.distractors_max >= 1 (a negative image shows distractors only)"));
  return p;
}

std::string DatasetSynthSummary::one_line() const {
  std::string line =
      fmt::format("wrote {} images ({} train, {} val) to {} in {:.1f} s ({:.2f} images/s, {} placements redrawn)",
                  images, train, val, out_dir, seconds, seconds > 0.0 ? images / seconds : 0.0, redrawn);
  if (distractors > 0 || negatives > 0)
    line += fmt::format(", {} distractors ({} labelled), {} images without a drone", distractors, distractors_labelled,
                        negatives);
  return line;
}

namespace {
/// The "sphere_box" of an image's metadata: the exact box of the target's bounding sphere (the box a sphere
/// detector would draw, not clipped to the image; `wingman model box-relation` relates a model's boxes to it), or
/// null when the sphere reaches behind the camera.
common::Json sphere_box_json(const geometry::CameraModel& camera, const Eigen::Vector3d& p_target_in_cam,
                             double radius_m) {
  const geometry::SphereImageBox s = geometry::project_sphere(camera, p_target_in_cam, radius_m);
  if (!s.valid) return nullptr;
  const geometry::PixelBox b = s.pixel_box();
  return {{"cx", b.cx}, {"cy", b.cy}, {"w", b.w}, {"h", b.h}};
}
}  // namespace

DatasetSynthSummary run_dataset_synth(const DatasetSynthRequest& request, std::ostream& progress) {
  if (request.count <= 0) throw std::invalid_argument(fmt::format("--count {}: must be > 0", request.count));
  if (request.out_dir.empty()) throw std::invalid_argument("--out: a dataset folder is required");
  DatasetSynthConfig config;  // the defaults are valid (tested)
  if (!request.config.empty()) config = common::load_options<DatasetSynthConfig>(request.config);
  return run_dataset_synth(request, config, progress);
}

DatasetSynthSummary run_dataset_synth(const DatasetSynthRequest& request, const DatasetSynthConfig& config,
                                      std::ostream& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (request.count <= 0) throw std::invalid_argument(fmt::format("--count {}: must be > 0", request.count));
  if (request.out_dir.empty()) throw std::invalid_argument("--out: a dataset folder is required");
  const fs::path out(request.out_dir);
  if (fs::exists(out / "images") && !fs::is_empty(out / "images")) {
    throw std::runtime_error(
        fmt::format("{}: already holds a dataset (images/ is not empty); choose a new --out", request.out_dir));
  }
  for (const char* kind : {"images", "labels", "meta"}) {
    for (const char* split : {"train", "val"}) fs::create_directories(out / kind / split);
  }

  // Airframes from mesh files, loaded once.
  std::vector<std::pair<sim::DroneSpec, std::shared_ptr<const sim::DroneModel>>> meshes;
  for (const std::string& file : mesh_files(request.meshes)) {
    sim::DroneSpec spec;
    spec.frame = "mesh";
    spec.mesh_path = file;
    meshes.emplace_back(spec, std::make_shared<const sim::DroneModel>(sim::DroneModel::from_spec(spec)));
  }

  // The camera pool: random lenses, one renderer each.
  std::vector<Camera> cameras;
  for (int k = 0; k < config.cameras; ++k) {
    Random rng(request.seed, kCameraStream, static_cast<uint64_t>(k));
    geometry::CameraModel model = random_camera(config, rng, k);
    auto renderer = std::make_unique<sim::Renderer>(model, config.render);
    cameras.push_back(
        Camera{model, std::move(renderer), sim::TruthBoxProjector(model, config.render.max_half_fov_deg)});
  }

  DatasetSynthSummary summary;
  summary.out_dir = request.out_dir;
  common::Progress images("wingman dataset synth", request.count, "images", &progress);
  for (int i = 0; i < request.count; ++i) {
    Random rng(request.seed, kImageStream, static_cast<uint64_t>(i));
    const std::string split = rng.chance(config.val_fraction) ? "val" : "train";
    const std::string name = fmt::format("{:06d}", i);
    bool negative = false;  // no drone, distractors only
    if (config.negative_fraction > 0.0) {
      Random negative_rng(request.seed, kNegativeStream, static_cast<uint64_t>(i));
      negative = negative_rng.chance(config.negative_fraction);
    }
    bool done = false;
    for (int attempt = 0; attempt < kMaxPlacements && !done; ++attempt) {
      Camera& camera = cameras[rng.index(cameras.size())];
      const sim::RenderOptions scene = random_scene(config, rng);
      // The target airframe.
      sim::DroneSpec spec;
      std::shared_ptr<const sim::DroneModel> model;
      if (!meshes.empty() && rng.chance(config.mesh_fraction)) {
        std::tie(spec, model) = meshes[rng.index(meshes.size())];
      } else {
        spec = random_airframe(config, rng);
        model = std::make_shared<const sim::DroneModel>(sim::DroneModel::procedural(spec));
      }
      // Camera pose, then the target somewhere in the image at a random range.
      const Eigen::Isometry3d T_cam_to_world = random_camera_pose(config, rng);
      const Eigen::Vector2d uv(rng.uniform(-0.5, config.width - 0.5), rng.uniform(-0.5, config.height - 0.5));
      const double range = rng.log_uniform(config.range_min_m, config.range_max_m);
      Eigen::Vector3d ray = camera.model.unproject(uv);
      if (config.horizon_fraction > 0.0 && rng.chance(config.horizon_fraction)) {
        // On the horizon: a world direction of small elevation within the camera's horizontal field of view.
        const Eigen::Vector3d z_cam_in_world = T_cam_to_world.linear().col(2);
        const double yaw = std::atan2(z_cam_in_world.y(), z_cam_in_world.x());
        const double azimuth = yaw + rng.uniform(-0.5, 0.5) * config.hfov_max_deg * kSynthDeg;
        const double elevation = rng.uniform(-1.0, 1.0) * config.horizon_elevation_max_deg * kSynthDeg;
        const Eigen::Vector3d d_in_world(std::cos(elevation) * std::cos(azimuth),
                                         std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
        ray = T_cam_to_world.linear().transpose() * d_in_world;  // unit ray in the optical frame
      }
      sim::DroneInstance target;
      target.vehicle_id = 1;
      target.model = model.get();
      const double tilt = config.target_tilt_max_deg * kSynthDeg;
      target.T_body_to_world.linear() =
          rpy(rng.uniform(-tilt, tilt), rng.uniform(-tilt, tilt), rng.uniform(-kSynthPi, kSynthPi));
      target.T_body_to_world.translation() = T_cam_to_world * (ray * range);
      target.v_body_in_world = rng.direction() * rng.uniform(0.0, 15.0);
      target.w_body_in_body = rng.direction() * rng.uniform(0.0, 1.0);
      target.prop_angle_rad = rng.uniform(0.0, 2.0 * kSynthPi);
      target.prop_rate_rad_s = rng.uniform(300.0, 900.0);
      sim::CameraMotion motion;
      motion.v_cam_in_world = rng.direction() * rng.uniform(0.0, 10.0);
      motion.w_cam_in_cam = rng.direction() * rng.uniform(0.0, 0.5);
      const uint64_t frame_seed = rng.next();
      const bool placeable = ray.allFinite() && camera.field_of_view.in_field_of_view(ray) &&
                             target.T_body_to_world.translation().z() > model->bounding_radius() + 0.3;
      if (!negative && !placeable) {
        ++summary.redrawn;
        continue;
      }
      // The distractors, from a stream of their own (nothing is drawn without them).
      std::vector<Distractor> distractors;
      if (config.distractors_max > 0) {
        Random distractor_rng(request.seed, kDistractorStream,
                              static_cast<uint64_t>(i) * kMaxPlacements + static_cast<uint64_t>(attempt));
        const auto max = static_cast<size_t>(config.distractors_max);
        const size_t n = negative ? 1 + distractor_rng.index(max) : distractor_rng.index(max + 1);
        distractors = place_distractors(config, camera.model, camera.field_of_view, T_cam_to_world, n, distractor_rng);
      }
      std::vector<sim::DroneInstance> instances;
      if (!negative) instances.push_back(target);
      for (size_t k = 0; k < distractors.size(); ++k) {
        distractors[k].instance.vehicle_id = static_cast<int>(2 + k);
        distractors[k].instance.model = distractors[k].model.get();
        instances.push_back(distractors[k].instance);
      }
      if (instances.empty()) {  // a negative whose distractors found no place
        ++summary.redrawn;
        continue;
      }
      camera.renderer->set_options(scene);
      const sim::RenderResult result = camera.renderer->render(T_cam_to_world, instances, 0, frame_seed, motion);
      const size_t first_distractor = negative ? 0 : 1;
      const auto seen = [&](const sim::RenderedBox& b) {
        return b.visible && b.visible_pixels >= config.min_visible_pixels;
      };
      if (!negative && !seen(result.boxes[0])) {
        ++summary.redrawn;
        continue;
      }
      if (negative && std::none_of(result.boxes.begin(), result.boxes.end(), seen)) {
        ++summary.redrawn;
        continue;
      }

      const std::string image_path = (out / "images" / split / (name + "." + config.image_format)).string();
      const std::vector<int> params = config.image_format == "jpg"
                                          ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, config.jpeg_quality}
                                          : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 3};
      if (!cv::imwrite(image_path, result.bgr, params))
        throw std::runtime_error(image_path + ": cannot write the image");
      const auto label_of = [&](int cls, const sim::RenderedBox& b) {
        training::LabeledBox label;
        label.cls = cls;
        label.cx = static_cast<float>(b.cx / config.width);
        label.cy = static_cast<float>(b.cy / config.height);
        label.w = static_cast<float>(b.w / config.width);
        label.h = static_cast<float>(b.h / config.height);
        return label;
      };
      std::vector<training::LabeledBox> labels;
      if (!negative) labels.push_back(label_of(0, result.boxes[0]));
      common::Json distractors_json = common::Json::array();
      for (size_t k = 0; k < distractors.size(); ++k) {
        const Distractor& d = distractors[k];
        const sim::RenderedBox& b = result.boxes[first_distractor + k];
        const bool labelled = config.distractor_classes && seen(b);
        if (labelled) labels.push_back(label_of(static_cast<int>(d.spec.kind), b));
        summary.distractors_labelled += labelled;
        distractors_json.push_back({{"kind", sim::distractor_name(d.spec.kind)},
                                    {"class_id", static_cast<int>(d.spec.kind)},
                                    {"spec",
                                     {{"span_m", d.spec.span_m},
                                      {"length_ratio", d.spec.length_ratio},
                                      {"wing_angle_deg", d.spec.wing_angle_deg},
                                      {"colour", d.spec.colour},
                                      {"accent_colour", d.spec.accent_colour}}},
                                    {"bounding_radius_m", d.model->bounding_radius()},
                                    {"T_body_to_world",
                                     {{"p", vec_json(d.instance.T_body_to_world.translation())},
                                      {"q_wxyz", quat_json(d.instance.T_body_to_world.linear())}}},
                                    {"prop_angle_rad", d.instance.prop_angle_rad},
                                    {"range_m", b.range_m},
                                    {"box", box_json(b)},
                                    {"labelled", labelled}});
        distractors_json.back()["box"]["visible"] = b.visible;
      }
      summary.distractors += static_cast<int>(distractors.size());
      training::write_yolo_labels((out / "labels" / split / (name + ".txt")).string(), labels);

      const geometry::CameraModel& cam = camera.model;
      const Eigen::Vector3d p_target_in_cam = T_cam_to_world.inverse() * target.T_body_to_world.translation();
      const std::string meta_path = (out / "meta" / split / (name + ".json")).string();
      common::Json j;
      j["image"] = "images/" + split + "/" + name + "." + config.image_format;
      j["width"] = config.width;
      j["height"] = config.height;
      j["camera"] = {{"name", cam.name()},
                     {"distortion_model", cam.model_name()},
                     {"fx", cam.fx()},
                     {"fy", cam.fy()},
                     {"cx", cam.cx()},
                     {"cy", cam.cy()},
                     {"coefficients", cam.coefficients()}};
      j["T_cam_to_world"] = {{"p", vec_json(T_cam_to_world.translation())},
                             {"q_wxyz", quat_json(T_cam_to_world.linear())}};
      if (!negative) {
        const sim::RenderedBox& box = result.boxes[0];
        j["target"] = {{"airframe", model->name()},
                       {"spec", spec_json(spec)},
                       {"bounding_radius_m", model->bounding_radius()},
                       {"frame_radius_m", model->frame_radius()},
                       {"T_body_to_world",
                        {{"p", vec_json(target.T_body_to_world.translation())},
                         {"q_wxyz", quat_json(target.T_body_to_world.linear())}}},
                       {"prop_angle_rad", target.prop_angle_rad},
                       {"p_target_in_cam", vec_json(p_target_in_cam)},
                       {"range_m", box.range_m}};
        j["box"] = box_json(box);
        j["sphere_box"] = sphere_box_json(cam, p_target_in_cam, model->bounding_radius());
      }
      if (config.distractors_max > 0) j["distractors"] = distractors_json;
      j["render"] = {{"scene_seed", scene.seed},
                     {"exposure_gain", result.exposure_gain},
                     {"noise_std", scene.noise_std},
                     {"shot_noise", scene.shot_noise},
                     {"motion_blur_exposure_s", scene.motion_blur_exposure_s},
                     {"frame_seed", frame_seed}};
      std::ofstream meta(meta_path);
      meta << common::json_text(j) << "\n";
      meta.close();
      if (!meta) throw std::runtime_error(meta_path + ": cannot write the metadata");
      ++summary.images;
      ++(split == "val" ? summary.val : summary.train);
      summary.negatives += negative;
      done = true;
    }
    if (!done) {
      throw std::runtime_error(
          fmt::format("image {}: no visible target in {} placements; widen synth.range_* or "
                      "lower synth.min_visible_pixels",
                      i, kMaxPlacements));
    }
    images.update(i + 1);
  }
  images.finish();
  training::write_data_yaml(
      (out / "data.yaml").string(),
      config.distractor_classes
          ? std::vector<std::string>(common::kDetectionClassNames.begin(), common::kDetectionClassNames.end())
          : std::vector<std::string>{common::kDetectionClassNames[common::kDroneClassId]},
      {"written by wingman dataset synth", fmt::format("seed {}, {} images", request.seed, request.count)});
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

namespace {

/// `wingman dataset synth`'s options as keys: the run's dataset.* and the configuration's synth.* and render.* (the
/// seed as an int64_t: the loader's integer).
struct SynthVerbOptions {
  std::string out;
  int count = 0;
  int64_t seed = static_cast<int64_t>(DatasetSynthRequest{}.seed);
  std::vector<std::string> meshes;
  DatasetSynthConfig config;

  template <class V>
  void visit(V& v) {
    v("dataset.out", out, "dataset folder to create (must not hold images yet)");
    v("dataset.count", count, "number of images");
    v("dataset.seed", seed, "the same seed gives the same dataset");
    v("dataset.meshes", meshes, "airframe mesh files or folders, e.g. ../shared/meshes");
    config.visit(v);
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p = config.validate();
    if (out.empty()) p.emplace_back("dataset.out: give the dataset folder (--out, or the key)");
    if (count <= 0) p.push_back(common::problem("dataset.count", count, "must be > 0"));
    if (seed < 0) p.push_back(common::problem("dataset.seed", static_cast<double>(seed), "must be >= 0"));
    return p;
  }
  DatasetSynthRequest request() const {
    DatasetSynthRequest r;
    r.out_dir = out;
    r.count = count;
    r.seed = static_cast<uint64_t>(seed);
    r.meshes = meshes;
    return r;
  }
};

}  // namespace

struct DatasetVerbs::State {
  CLI::App* synth = nullptr;
  DatasetSynthRequest request;  // what the flags say; synth runs with what its layers load
  std::unique_ptr<VerbLayers> synth_layers;
  CLI::App* from_log = nullptr;
  DatasetFromLogRequest from_log_request;
  bool skip_negatives = false;
};

DatasetVerbs::DatasetVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  CLI::App* dataset = app.add_subcommand(
      "dataset", "Datasets: render synthetic training images, or take them from a simulated flight's log");
  dataset->require_subcommand(1);
  s_->synth = dataset->add_subcommand(
      "synth",
      "Render labelled images of drones with domain randomization (YOLO layout, data.yaml, per-image metadata)");
  s_->synth->add_option("--out", s_->request.out_dir, "Dataset folder to create (must not hold images yet)")
      ->required();
  s_->synth->add_option("--count", s_->request.count, "Number of images")->required()->check(CLI::PositiveNumber);
  s_->synth->add_option("--seed", s_->request.seed, "Seed: the same seed gives the same dataset");
  s_->synth->add_option("--meshes", s_->request.meshes,
                        "Airframe mesh file or folder (repeatable), e.g. ../shared/meshes");
  s_->synth_layers = std::make_unique<VerbLayers>(s_->synth);  // --config: synth.* and render.* keys too
  s_->synth_layers->keys({
      {"--out", "dataset.out", true},
      {"--count", "dataset.count", false},
      {"--seed", "dataset.seed", false},
      {"--meshes", "dataset.meshes", true},
  });

  DatasetFromLogRequest& f = s_->from_log_request;
  s_->from_log = dataset->add_subcommand(
      "from-log",
      "Camera frames of simulated flights' logs (tools/fly.sh --record-images) with the renderer's ground-truth "
      "boxes, as a YOLO dataset");
  s_->from_log->add_option("logs", f.logs, "LCM logs with images and GROUND_TRUTH")->required();
  s_->from_log->add_option("--out", f.out_dir, "Dataset folder (created, or extended with more logs)")->required();
  s_->from_log->add_option("--split", f.split, "train or val: where all images of these logs go");
  s_->from_log->add_option("--every", f.every, "Keep every Nth image of each log");
  s_->from_log->add_option("--min-box-px", f.min_box_px,
                           "Drop visible boxes narrower or lower than this after clipping, pixels");
  s_->from_log->add_flag("--skip-negatives", s_->skip_negatives, "Leave out frames without a visible drone");
  s_->from_log->add_option("--format", f.image_format, "Image format: jpg or png");
  s_->from_log->add_option("--jpeg-quality", f.jpeg_quality, "JPEG quality 1..100");
  s_->from_log->add_option("--image-channel", f.image_channel, "image_t channel");
  s_->from_log->add_option("--truth-channel", f.truth_channel, "ground_truth_t channel");
}

DatasetVerbs::~DatasetVerbs() = default;

int DatasetVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  if (*s_->from_log) {
    return run_verb("wingman dataset from-log", err, [&] {
      s_->from_log_request.keep_negatives = !s_->skip_negatives;
      out << run_dataset_from_log(s_->from_log_request, err).one_line() << std::endl;
      return 0;
    });
  }
  if (!*s_->synth) return -1;
  int rc = -1;
  const auto o = s_->synth_layers->load_or_exit<SynthVerbOptions>(out, err, &rc);
  if (!o) return rc;
  return run_verb("wingman dataset synth", err, [&] {
    out << run_dataset_synth(o->request(), o->config, err).one_line() << std::endl;
    return 0;
  });
}

}  // namespace wingman::tools
