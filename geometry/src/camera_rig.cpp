// SPDX-License-Identifier: MIT
// Reading a camera rig file (camera_rig.hpp).
#include "wingman/geometry/camera_rig.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <wingman/common/config.hpp>
#include <wingman/common/yaml_limits.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace wingman::geometry {
namespace fs = std::filesystem;

const RigCamera* CameraRig::find(int camera_id) const {
  for (const RigCamera& c : cameras)
    if (c.camera.camera_id == camera_id) return &c;
  return nullptr;
}

namespace {

/// R_cam_to_body of the default forward camera turned left by `yaw_deg` about body z, then tilted up by
/// `pitch_deg`, row-major.
std::vector<double> mount_rotation(double yaw_deg, double pitch_deg) {
  const ExtrinsicsOptions defaults;
  Eigen::Matrix3d R_forward;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_forward(r, c) = defaults.R_cam_to_body[static_cast<size_t>(3 * r + c)];
  const double deg = M_PI / 180.0;
  // Tilting up turns the optical axis (body +x) towards body +z: a rotation about body y by -pitch.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw_deg * deg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-pitch_deg * deg, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix() *
                            R_forward;
  std::vector<double> out(9);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[static_cast<size_t>(3 * r + c)] = R(r, c);
  return out;
}

}  // namespace

CameraRig load_camera_rig(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw common::ConfigError(fmt::format("{}: cannot read the camera rig file", path));
  std::ostringstream text;
  text << in.rdbuf();
  if (const std::string bad = common::check_yaml_bounds(text.str(), path); !bad.empty()) throw common::ConfigError(bad);
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw common::ConfigError(fmt::format("{}:{}: not valid YAML: {}", path, e.mark.line + 1, e.msg));
  }

  CameraRig rig;
  rig.source = path;
  std::vector<std::string> problems;
  common::YamlMappingReader top(path, root, "", &problems);
  const std::vector<YAML::Node> items = top.take_list("cameras", true);
  top.finish(" (a rig file has one key, cameras: a list of cameras)");
  if (items.empty() && problems.empty()) problems.push_back(fmt::format("{}: cameras: the list is empty", path));
  if (static_cast<int>(items.size()) > CameraRig::kMaxCameras)
    problems.push_back(fmt::format("{}: cameras: {} cameras, at most {}", path, items.size(), CameraRig::kMaxCameras));

  const fs::path folder = fs::path(path).parent_path();
  std::map<int, size_t> ids;
  std::map<std::string, std::string> channels;  // channel -> "cameras[i].channels.x"
  for (size_t i = 0; i < items.size() && static_cast<int>(i) < CameraRig::kMaxCameras; ++i) {
    const std::string prefix = fmt::format("cameras[{}].", i);
    common::YamlMappingReader r(path, items[i], prefix, &problems);
    RigCamera cam;
    cam.camera.visit(r);
    const bool has_R = r.has("extrinsics.R_cam_to_body");
    cam.extrinsics.visit(r);
    double yaw_deg = 0.0, pitch_deg = 0.0;
    const bool has_mount = r.has("mount.yaw_deg") || r.has("mount.pitch_deg");
    r("mount.yaw_deg", yaw_deg, "turned left about body z from the forward camera, degrees");
    r("mount.pitch_deg", pitch_deg, "tilted up, degrees");
    r("channels.image", cam.image_channel, "image_t channel");
    r("channels.detections", cam.detections_channel, "detections_t channel");
    r("channels.windows", cam.windows_channel, "track_windows_t channel");
    r.finish(" (a rig camera takes camera.*, extrinsics.*, mount.yaw_deg, mount.pitch_deg, channels.*)");

    if (has_mount && has_R)
      r.problem("mount.yaw_deg", "give the mount either as mount.yaw_deg/pitch_deg or as extrinsics.R_cam_to_body");
    if (!std::isfinite(yaw_deg) || !std::isfinite(pitch_deg))
      r.problem("mount.yaw_deg", "mount.yaw_deg and mount.pitch_deg must be finite");
    else if (has_mount)
      cam.extrinsics.R_cam_to_body = mount_rotation(yaw_deg, pitch_deg);

    for (const std::string& line : cam.camera.validate()) r.validation_problem(line);
    for (const std::string& line : cam.extrinsics.validate()) r.validation_problem(line);
    if (!cam.camera.calibration.empty()) {
      fs::path calib(cam.camera.calibration);
      if (calib.is_relative()) calib = folder / calib;
      if (!fs::is_regular_file(calib))
        r.problem(
            "camera.calibration",
            fmt::format("'{}' is not a file (a relative path is taken from the rig file's folder)", calib.string()));
      cam.camera.calibration = calib.string();
    }

    const int id = cam.camera.camera_id;
    if (const auto it = ids.find(id); it != ids.end())
      r.problem("camera.camera_id", fmt::format("{} is also cameras[{}]'s", id, it->second));
    else
      ids[id] = i;
    if (cam.image_channel.empty()) cam.image_channel = fmt::format("IMAGE_CAM{}", id);
    if (cam.detections_channel.empty()) cam.detections_channel = fmt::format("DETECTIONS_CAM{}", id);
    if (cam.windows_channel.empty()) cam.windows_channel = fmt::format("WINDOWS_CAM{}", id);
    const std::pair<const char*, const std::string*> named[] = {{"channels.image", &cam.image_channel},
                                                                {"channels.detections", &cam.detections_channel},
                                                                {"channels.windows", &cam.windows_channel}};
    for (const auto& [key, channel] : named) {
      const auto [it, inserted] = channels.emplace(*channel, prefix + key);
      if (!inserted) r.problem(key, fmt::format("'{}' is also {}", *channel, it->second));
    }
    rig.cameras.push_back(std::move(cam));
  }
  if (!problems.empty()) {
    std::string message =
        fmt::format("{}: {} problem{} in the camera rig:", path, problems.size(), problems.size() == 1 ? "" : "s");
    for (const std::string& p : problems) message += "\n  " + p;
    throw common::ConfigError(message);
  }
  return rig;
}

}  // namespace wingman::geometry
