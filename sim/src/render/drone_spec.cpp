// SPDX-License-Identifier: MIT
// Validation of DroneSpec.
#include "wingman/sim/drone_spec.hpp"

#include "colour.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>

namespace wingman::sim {

int DroneSpec::arm_count() const {
  if (frame == "quad") return 4;
  if (frame == "hex") return 6;
  if (frame == "octo") return 8;
  return 0;
}

std::vector<std::string> DroneSpec::validate(const std::string& prefix) const {
  using common::problem;
  std::vector<std::string> p;
  const auto key = [&](const char* name) { return prefix + name; };
  const auto positive = [&](const char* name, double value, double max) {
    if (!(value > 0.0 && value <= max)) p.push_back(problem(key(name), value, fmt::format("must be in (0, {}]", max)));
  };
  if (frame != "quad" && frame != "hex" && frame != "octo" && frame != "mesh") {
    p.push_back(problem(key("frame"), frame, "must be quad, hex, octo or mesh"));
  }
  if (frame == "mesh") {
    if (mesh_path.empty())
      p.push_back(problem(key("mesh_path"), mesh_path, "must name a mesh file when frame is mesh"));
    if (!(mesh_scale > 0.0 && std::isfinite(mesh_scale)))
      p.push_back(problem(key("mesh_scale"), mesh_scale, "must be > 0"));
    if (mesh_rpy_deg.size() != 3 || !std::isfinite(mesh_rpy_deg[0] + mesh_rpy_deg[1] + mesh_rpy_deg[2])) {
      p.push_back(problem(key("mesh_rpy_deg"), fmt::format("[{}]", fmt::join(mesh_rpy_deg, ", ")),
                          "expected 3 finite numbers [roll, pitch, yaw] in degrees"));
    }
    if (mesh_prop_axes_m.size() % 2 != 0 ||
        !std::all_of(mesh_prop_axes_m.begin(), mesh_prop_axes_m.end(), [](double v) { return std::isfinite(v); })) {
      p.push_back(problem(key("mesh_prop_axes_m"), fmt::format("[{}]", fmt::join(mesh_prop_axes_m, ", ")),
                          "expected finite pairs x, y (metres)"));
    }
    try {
      std::regex(mesh_prop_pattern, std::regex::ECMAScript | std::regex::icase);
    } catch (const std::regex_error& e) {
      p.push_back(problem(key("mesh_prop_pattern"), mesh_prop_pattern,
                          std::string("not a valid regular expression: ") + e.what()));
    }
    return p;
  }
  positive("arm_length_m", arm_length_m, 5.0);
  positive("arm_width_m", arm_width_m, 1.0);
  positive("body_size_m", body_size_m, 5.0);
  positive("body_height_m", body_height_m, 2.0);
  positive("motor_radius_m", motor_radius_m, 1.0);
  positive("motor_height_m", motor_height_m, 1.0);
  positive("prop_diameter_m", prop_diameter_m, 5.0);
  positive("prop_chord_m", prop_chord_m, 1.0);
  positive("prop_thickness_m", prop_thickness_m, 0.1);
  if (!(gear_height_m >= 0.0 && gear_height_m <= 2.0)) {
    p.push_back(problem(key("gear_height_m"), gear_height_m, "must be in [0, 2] (0 = no landing gear)"));
  }
  if (gear_height_m > 0.0) {
    positive("gear_width_m", gear_width_m, 5.0);
    positive("gear_length_m", gear_length_m, 5.0);
    positive("gear_tube_m", gear_tube_m, 0.5);
  }
  if (prop_blades < 2 || prop_blades > 6) p.push_back(problem(key("prop_blades"), prop_blades, "must be in 2..6"));
  if (prop_style != "blades" && prop_style != "disc") {
    p.push_back(problem(key("prop_style"), prop_style, "must be blades or disc"));
  }
  if (!(prop_disc_alpha > 0.0 && prop_disc_alpha <= 1.0)) {
    p.push_back(problem(key("prop_disc_alpha"), prop_disc_alpha, "must be in (0, 1]"));
  }
  if (motor_radius_m > 0.0 && arm_width_m > 0.0 && motor_radius_m * 2.0 > arm_length_m) {
    p.push_back(problem(key("motor_radius_m"), motor_radius_m, "must be at most half of arm_length_m"));
  }
  if (prop_chord_m > 0.0 && prop_diameter_m > 0.0 && prop_chord_m * 2.0 > prop_diameter_m) {
    p.push_back(problem(key("prop_chord_m"), prop_chord_m, "must be at most half of prop_diameter_m"));
  }
  detail::check_colour_key(key("body_colour"), body_colour, p);
  detail::check_colour_key(key("front_arm_colour"), front_arm_colour, p);
  detail::check_colour_key(key("rear_arm_colour"), rear_arm_colour, p);
  detail::check_colour_key(key("motor_colour"), motor_colour, p);
  detail::check_colour_key(key("prop_colour"), prop_colour, p);
  detail::check_colour_key(key("gear_colour"), gear_colour, p);
  return p;
}

}  // namespace wingman::sim
