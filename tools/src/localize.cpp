// SPDX-License-Identifier: MIT
// `wingman localize`: calibration + radius + box -> direction, range, camera-frame position (text or JSON).
#include "wingman/tools/localize.hpp"

#include <fmt/format.h>
#include <wingman/common/json.hpp>
#include <wingman/geometry/calibration.hpp>

#include <cmath>
#include <exception>
#include <optional>
#include <regex>

namespace wingman::tools {

namespace {

std::string vec(const Eigen::Vector3d& v, int precision) {
  return fmt::format("[{:.{}f}, {:.{}f}, {:.{}f}]", v.x(), precision, v.y(), precision, v.z(), precision);
}

common::Json json_vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

int run_localize(const LocalizeToolOptions& o, std::ostream& out, std::ostream& err) {
  const auto fail = [&err](int code, const std::string& message) {
    err << "wingman localize: error: " << message << std::endl;
    return code;
  };
  // Arguments.
  if (o.box.size() != 4) return fail(2, fmt::format("--box needs 4 numbers cx,cy,w,h, got {}", o.box.size()));
  if (const auto problems = o.localizer.validate(); !problems.empty())
    return fail(2, fmt::format("{}", fmt::join(problems, "; ")));
  int image_w = 0, image_h = 0;
  if (!o.image_size.empty()) {
    std::smatch m;
    if (!std::regex_match(o.image_size, m, std::regex(R"((\d{1,6})x(\d{1,6}))")))
      return fail(2, fmt::format("--image-size = '{}': expected WIDTHxHEIGHT, e.g. 1280x720", o.image_size));
    image_w = std::stoi(m[1]);
    image_h = std::stoi(m[2]);
    if (image_w <= 0 || image_h <= 0)
      return fail(2, fmt::format("--image-size = '{}': sides must be > 0", o.image_size));
  } else if (o.scale_calibration) {
    return fail(2, "--scale-calibration needs --image-size");
  }

  // Calibration.
  std::optional<geometry::CameraModel> loaded;
  try {
    loaded = geometry::load_calibration(o.calibration, o.kalibr_camera);
  } catch (const geometry::CalibrationError& e) {
    return fail(1, e.what());
  }
  geometry::CameraModel camera = *loaded;
  if (image_w > 0) {
    if (const std::string bad = camera.check_image_size(image_w, image_h); !bad.empty()) {
      if (!o.scale_calibration) return fail(1, fmt::format("{}: {}", o.calibration, bad));
      camera = camera.scaled_to(image_w, image_h);
    }
  }

  // Localization.
  const geometry::PixelBox box{o.box[0], o.box[1], o.box[2], o.box[3]};
  const localizer::LocalizeResult r = localizer::localize_box(box, camera, o.localizer);
  if (!r.ok) return fail(1, r.reason);
  const localizer::CameraMeasurement& m = r.measurement;
  const double sigma_range = m.range_valid ? std::sqrt(m.bearing_in_cam.dot(m.cov_p_in_cam * m.bearing_in_cam)) : 0;

  if (o.json) {
    common::Json j;
    j["ok"] = true;
    j["calibration"] = o.calibration;
    j["camera"] = camera.model_name();
    j["image_size"] = {camera.width(), camera.height()};
    j["radius_m"] = o.localizer.radius_m;
    j["method"] = o.localizer.range_method;
    j["box"] = {box.cx, box.cy, box.w, box.h};
    j["direction_in_cam"] = json_vec(m.bearing_in_cam);
    j["range_valid"] = m.range_valid;
    if (m.range_valid) {
      const Eigen::Matrix3d& c = m.cov_p_in_cam;
      j["range_m"] = m.range;
      j["range_sigma_m"] = sigma_range;
      j["p_target_in_cam"] = json_vec(m.p_target_in_cam);
      j["cov_p_in_cam"] = {json_vec(c.row(0).transpose()), json_vec(c.row(1).transpose()),
                           json_vec(c.row(2).transpose())};
    }
    j["edges_used"] = r.edges_used;
    out << common::json_text(j) << std::endl;
    return 0;
  }
  out << "camera:    " << camera.describe() << "  (" << o.calibration << ")\n";
  out << fmt::format("box:       cx={} cy={} w={} h={} px (origin at the top-left pixel's corner)\n", box.cx, box.cy,
                     box.w, box.h);
  out << fmt::format("target:    sphere of radius {} m, method {}\n", o.localizer.radius_m, o.localizer.range_method);
  out << "direction: " << vec(m.bearing_in_cam, 6) << "  (unit, camera optical frame: x right, y down, z forward)\n";
  if (m.range_valid) {
    out << fmt::format("range:     {:.3f} m  (1 sigma {:.3f} m, from {} box edges)\n", m.range, sigma_range,
                       r.edges_used);
    out << "position:  " << vec(m.p_target_in_cam, 3) << " m  (camera optical frame)\n";
    out << fmt::format("sigma:     x {:.3f} m, y {:.3f} m, z {:.3f} m\n", std::sqrt(m.cov_p_in_cam(0, 0)),
                       std::sqrt(m.cov_p_in_cam(1, 1)), std::sqrt(m.cov_p_in_cam(2, 2)));
  } else {
    out << "range:     none: the box is cut by the image border on both axes (bearing only)\n";
  }
  out << std::flush;
  return 0;
}

}  // namespace wingman::tools
