// SPDX-License-Identifier: MIT
// Scenario files: parsing with every problem reported at once.
#include "wingman/sim/scenario.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <wingman/common/yaml_limits.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace wingman::sim {
namespace {

using common::YamlMappingReader;
constexpr double kDegToRad = M_PI / 180.0;

/// Reads the 3-vector leaf `key` ([x, y, z]) into `value`; absent or not three numbers: `value` is kept.
void read_vector3(YamlMappingReader& r, const std::string& key, Eigen::Vector3d& value) {
  std::array<double, 3> xyz{value.x(), value.y(), value.z()};
  r(key, xyz, "");
  value = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
}

MotionSpec::Type parse_motion_type(const std::string& text, bool* ok) {
  *ok = true;
  if (text == "hover") return MotionSpec::Type::kHover;
  if (text == "random_walk") return MotionSpec::Type::kRandomWalk;
  if (text == "waypoints") return MotionSpec::Type::kWaypoints;
  if (text == "teleport_steps") return MotionSpec::Type::kTeleportSteps;
  *ok = false;
  return MotionSpec::Type::kHover;
}

void read_waypoints(YamlMappingReader& vr, MotionSpec& m, std::vector<std::string>* problems) {
  const YAML::Node list = vr.take("motion.waypoints");
  if (!list.IsDefined()) {
    vr.problem("motion.waypoints", "missing: motion.type waypoints needs a list of {position, speed, stop_s, yaw_deg}");
    return;
  }
  if (!list.IsSequence()) {
    vr.problem("motion.waypoints", "expected a sequence of mappings {position, speed, stop_s, yaw_deg}, got " +
                                       YamlMappingReader::describe(list));
    return;
  }
  for (size_t i = 0; i < list.size(); ++i) {
    YamlMappingReader wr(vr.source_name(), list[i], fmt::format("{}motion.waypoints[{}].", vr.path_prefix(), i),
                         problems);
    Waypoint w;
    if (!wr.has("position")) wr.problem("position", "missing: every waypoint needs position [x, y, z]");
    read_vector3(wr, "position", w.p_in_world);
    wr("speed", w.speed, "");
    wr("stop_s", w.stop_s, "");
    if (wr.has("yaw_deg")) {
      double yaw_deg = 0;
      wr("yaw_deg", yaw_deg, "");
      w.yaw_rad = yaw_deg * kDegToRad;
    }
    wr.finish();
    m.waypoints.push_back(w);
  }
}

void read_motion(YamlMappingReader& vr, VehicleSpec& v, std::vector<std::string>* problems) {
  MotionSpec& m = v.motion;
  std::string type = "hover";
  vr("motion.type", type, "");
  bool ok = true;
  m.type = parse_motion_type(type, &ok);
  if (!ok) {
    vr.problem("motion.type",
               fmt::format("'{}' is not a motion type: hover, random_walk, waypoints or teleport_steps", type));
    return;
  }
  switch (m.type) {
    case MotionSpec::Type::kHover:
      break;
    case MotionSpec::Type::kRandomWalk:
      if (!vr.has("motion.from")) vr.problem("motion.from", "missing: random_walk needs the segment's from [x, y, z]");
      if (!vr.has("motion.to")) vr.problem("motion.to", "missing: random_walk needs the segment's to [x, y, z]");
      read_vector3(vr, "motion.from", m.segment_from);
      read_vector3(vr, "motion.to", m.segment_to);
      vr("motion.max_speed", m.max_speed, "");
      m.min_speed = m.max_speed;  // default: every leg at max_speed
      vr("motion.min_speed", m.min_speed, "");
      vr("motion.max_pause_s", m.max_pause_s, "");
      vr("motion.accel", m.accel, "");
      vr("motion.seed", m.seed, "");
      break;
    case MotionSpec::Type::kWaypoints:
      read_waypoints(vr, m, problems);
      vr("motion.accel", m.accel, "");
      vr("motion.loop", m.loop, "");
      break;
    case MotionSpec::Type::kTeleportSteps:
      if (!vr.has("motion.step")) vr.problem("motion.step", "missing: teleport_steps needs step [dx, dy, dz]");
      if (!vr.has("motion.steps")) vr.problem("motion.steps", "missing: teleport_steps needs the number of steps");
      read_vector3(vr, "motion.step", m.step);
      vr("motion.steps", m.steps, "");
      vr("motion.frames_per_step", m.frames_per_step, "");
      break;
  }
}

VehicleSpec read_vehicle(const std::string& source, const YAML::Node& node, size_t index, const std::string& base_dir,
                         std::vector<std::string>* problems) {
  VehicleSpec v;
  YamlMappingReader vr(source, node, fmt::format("vehicles[{}].", index), problems);
  if (node.IsDefined() && !node.IsNull() && !node.IsMap()) return v;  // not a mapping: the reader said so
  if (!vr.has("name")) vr.problem("name", "missing: every vehicle needs a name");
  if (!vr.has("id")) vr.problem("id", "missing: every vehicle needs an id (0 = the camera vehicle)");
  if (!vr.has("initial.position")) vr.problem("initial.position", "missing: every vehicle needs initial.position");
  vr("name", v.name, "");
  vr("id", v.id, "");
  std::string control = v.id == 0 ? "setpoints" : "script";
  vr("control", control, "");
  if (control == "setpoints") {
    v.control = VehicleSpec::Control::kSetpoints;
    if (v.id != 0) vr.problem("control", "'setpoints': only the camera vehicle (id 0) takes setpoints; use script");
  } else if (control == "script") {
    v.control = VehicleSpec::Control::kScript;
  } else {
    vr.problem("control", fmt::format("'{}': must be setpoints or script", control));
  }
  read_vector3(vr, "initial.position", v.p_initial_in_world);
  double yaw_deg = 0;
  vr("initial.yaw_deg", yaw_deg, "");
  v.yaw_initial_rad = yaw_deg * kDegToRad;
  if (!v.p_initial_in_world.allFinite()) vr.problem("initial.position", "must be finite");
  if (!std::isfinite(yaw_deg)) vr.problem("initial.yaw_deg", "must be finite");
  v.drone.visit(vr, "drone.");
  v.dynamics.visit(vr, "dynamics.");
  const bool has_motion = vr.has("motion.type");
  read_motion(vr, v, problems);
  if (v.control == VehicleSpec::Control::kSetpoints && has_motion) {
    vr.problem("motion.type", "a vehicle with control: setpoints has no motion script (use control: script)");
  }
  vr.finish(fmt::format(" (motion.type {} takes other keys; see docs/simulation.md)", motion_type_name(v.motion.type)));

  for (const auto& p : v.drone.validate("drone.")) vr.validation_problem(p);
  for (const auto& p : v.dynamics.validate("dynamics.")) vr.validation_problem(p);
  if (v.control == VehicleSpec::Control::kScript) {
    for (const auto& p : validate_motion(v.motion, v.p_initial_in_world)) vr.validation_problem("motion." + p);
  }
  if (v.name.empty() && vr.has("name")) vr.problem("name", "must not be empty");
  if (v.id < 0) vr.problem("id", fmt::format("{}: must be >= 0", v.id));
  // Relative mesh paths are relative to the scenario file.
  if (!v.drone.mesh_path.empty() && !base_dir.empty() && std::filesystem::path(v.drone.mesh_path).is_relative()) {
    v.drone.mesh_path = (std::filesystem::path(base_dir) / v.drone.mesh_path).lexically_normal().string();
  }
  return v;
}

bool finite_script(const VehicleSpec& v) {
  if (v.control != VehicleSpec::Control::kScript) return false;
  return v.motion.type == MotionSpec::Type::kTeleportSteps ||
         (v.motion.type == MotionSpec::Type::kWaypoints && !v.motion.loop);
}

}  // namespace

const VehicleSpec& Scenario::camera_vehicle() const {
  for (const auto& v : vehicles) {
    if (v.id == 0) return v;
  }
  throw std::logic_error("scenario " + name + ": no vehicle with id 0");
}

Scenario parse_scenario(const std::string& yaml_text, const std::string& source_name, const std::string& base_dir) {
  // Size and alias expansion bounded before yaml-cpp builds anything (a 663-byte alias bomb took 4.2 GB).
  if (const std::string bad = common::check_yaml_bounds(yaml_text, source_name); !bad.empty()) throw ScenarioError(bad);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ScenarioError(
        fmt::format("{}:{}:{}: not valid YAML: {}", source_name, e.mark.line + 1, e.mark.column + 1, e.msg));
  }
  std::vector<std::string> problems;
  Scenario s;
  s.source = source_name;
  s.name = std::filesystem::path(source_name).stem().string();
  if (!root.IsMap()) {
    throw ScenarioError(
        fmt::format("{}: expected a mapping with name, start_utime, vehicles, ... at the top level, got {}",
                    source_name, YamlMappingReader::describe(root)));
  }
  YamlMappingReader top(source_name, root, "", &problems);
  top("name", s.name, "");
  top("description", s.description, "");
  top("start_utime", s.start_utime, "");
  top("duration_s", s.duration_s, "");
  top("command_delay_s", s.command_delay_s, "");
  top("seed", s.seed, "");
  const YAML::Node vehicles = top.take("vehicles");
  top.finish();
  if (s.start_utime < 0)
    top.problem("start_utime", fmt::format("{}: must be >= 0 (microseconds since epoch)", s.start_utime));
  if (!(s.duration_s >= 0) || !std::isfinite(s.duration_s))
    top.problem("duration_s", fmt::format("{}: must be >= 0 (0 = until the scripts end)", s.duration_s));
  if (!(s.command_delay_s >= 0 && s.command_delay_s <= 10))
    top.problem("command_delay_s", fmt::format("{}: must be in [0, 10] seconds", s.command_delay_s));

  if (!vehicles.IsDefined()) {
    top.problem("vehicles", "missing: a scenario needs a list of vehicles (id 0 = the camera vehicle)");
  } else if (!vehicles.IsSequence() || vehicles.size() == 0) {
    top.problem("vehicles", "expected a non-empty sequence of vehicles, got " + YamlMappingReader::describe(vehicles));
  } else {
    for (size_t i = 0; i < vehicles.size(); ++i) {
      s.vehicles.push_back(read_vehicle(source_name, vehicles[i], i, base_dir, &problems));
    }
    std::map<int, size_t> ids;
    std::map<std::string, size_t> names;
    for (size_t i = 0; i < s.vehicles.size(); ++i) {
      const auto& v = s.vehicles[i];
      if (auto [it, fresh] = ids.emplace(v.id, i); !fresh)
        problems.push_back(fmt::format("{}: vehicles[{}].id: {} is also the id of vehicles[{}]; ids must be unique",
                                       source_name, i, v.id, it->second));
      if (v.name.empty()) continue;
      if (auto [it, fresh] = names.emplace(v.name, i); !fresh)
        problems.push_back(
            fmt::format("{}: vehicles[{}].name: '{}' is also the name of vehicles[{}]; names must be unique",
                        source_name, i, v.name, it->second));
    }
    if (!ids.count(0)) {
      problems.push_back(fmt::format("{}: vehicles: no vehicle has id 0 (the camera vehicle)", source_name));
    }
    if (s.duration_s == 0) {
      bool any_finite = false;
      for (const auto& v : s.vehicles) any_finite = any_finite || finite_script(v);
      if (!any_finite)
        top.problem("duration_s",
                    "0 (until the scripts end) needs a script that ends (teleport_steps, or waypoints "
                    "without loop); give a duration");
    }
  }
  if (!problems.empty()) {
    std::string msg = fmt::format("{} problem{} in scenario: ", problems.size(), problems.size() == 1 ? "" : "s");
    for (size_t i = 0; i < problems.size(); ++i) msg += (i ? "; " : "") + problems[i];
    throw ScenarioError(msg);
  }
  return s;
}

Scenario load_scenario(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ScenarioError(fmt::format("{}: cannot open scenario file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scenario(ss.str(), path, std::filesystem::path(path).parent_path().string());
}

}  // namespace wingman::sim
