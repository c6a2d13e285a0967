// SPDX-License-Identifier: MIT
// `wingman scenario random`: a seeded random formation flight for wingman-sim, with the configs fly.sh flies it with.
#include "wingman/tools/scenario_random.hpp"

#include "wingman/tools/scenario_edit.hpp"

#include "run_verb.hpp"
#include "synth_random.hpp"
#include "verb_layers.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/json.hpp>
#include <wingman/sim/drone_model.hpp>
#include <wingman/sim/scenario.hpp>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;

// Random streams: one per purpose, so that a change in one draw leaves the others alone.
enum ScenarioStream : uint64_t { kPathStream = 11, kSceneStream = 12, kAirframeStream = 13 };

// The localizer's keys this flight sets: the leader's true size, and the shortest range accepted, which must exceed
// it (the localizer's defaults for everything else).
struct LocalizerTarget {
  double radius_m = 0.348;
  double min_range_m = 0.5;
  template <class V>
  void visit(V& v) {
    v("target.radius_m", radius_m,
      "the leader's bounding-sphere radius, propellers spinning, metres (the simulator's)");
    v("range.min_m", min_range_m, "the localizer's default 0.5 m, or 1.5 x the radius where that is larger");
  }
  std::vector<std::string> validate() const {
    if (radius_m > 0.0 && std::isfinite(radius_m) && min_range_m > radius_m) return {};
    return {common::problem("target.radius_m", radius_m, "must be > 0 and < range.min_m")};
  }
};

// The follower's keys this flight sets: the formation offset, and the leader's height followed.
struct FollowerFormation {
  std::vector<double> offset_m = {0.0, -6.0, 0.0};
  std::string height_mode = "target";
  template <class V>
  void visit(V& v) {
    v("formation.offset_m", offset_m, "follower position relative to the leader, ENU [east, north, up], m");
    v("formation.height_mode", height_mode, "target: keep the offset's height above the leader as it climbs");
  }
  std::vector<std::string> validate() const { return {}; }
};

// The simulator's render.* keys (its config's other keys keep their defaults).
struct RenderSection {
  sim::RenderOptions render;
  template <class V>
  void visit(V& v) {
    render.visit(v);
  }
  std::vector<std::string> validate() const { return render.validate(); }
};

// A DroneSpec as the scenario's `drone:` mapping, one "key: value" line each at `indent`.
class YamlSpecWriter {
 public:
  explicit YamlSpecWriter(std::string indent) : indent_(std::move(indent)) {}
  template <class T>
  void operator()(const std::string& key, const T& value, const char* /*doc*/) {
    text_ += indent_ + key + ": " + format(value) + "\n";
  }
  const std::string& str() const { return text_; }

 private:
  static std::string format(int v) { return std::to_string(v); }
  static std::string format(double v) { return fmt::format("{:.9g}", v); }
  static std::string format(const std::string& v) {
    std::string out = "\"";
    for (char ch : v) {
      if (ch == '"' || ch == '\\') out += '\\';
      out += ch;
    }
    return out + "\"";
  }
  static std::string format(const std::vector<double>& v) { return fmt::format("[{:.9g}]", fmt::join(v, ", ")); }
  std::string indent_, text_;
};

std::string vec(const Eigen::Vector3d& p) { return fmt::format("[{:.4f}, {:.4f}, {:.4f}]", p.x(), p.y(), p.z()); }

// Seconds to fly a straight leg of `length_m` from rest to rest at cruise `speed` with acceleration `accel`.
double leg_time_s(double length_m, double speed, double accel) {
  if (length_m >= speed * speed / accel) return length_m / speed + speed / accel;
  return 2.0 * std::sqrt(length_m / accel);  // never reaches the cruise speed
}

// The two lighting set-ups, applied over the scene drawn for the seed.
void apply_lighting(const std::string& lighting, sim::RenderOptions& o) {
  o.exposure_jitter = 0.0;
  o.motion_blur_exposure_s = 0.0;  // as the other flights: no blur (it multiplies the rendering time)
  o.noise_std = 1.5;
  o.shot_noise = 0.3;
  if (lighting == "A") {  // midday, clear
    o.sun_azimuth_deg = 135.0;
    o.sun_elevation_deg = 45.0;
    o.sun_intensity = 1.0;
    o.ambient_intensity = 0.45;
    o.sky_zenith_colour = {0.25, 0.45, 0.8};
    o.sky_horizon_colour = {0.75, 0.82, 0.9};
    o.cloud_cover = 0.3;
    o.visibility_m = 8000.0;
    o.exposure_gain = 1.0;
  } else {  // B: evening, low sun in the west, warm haze, clouds, less light
    o.sun_azimuth_deg = 280.0;
    o.sun_elevation_deg = 8.0;
    o.sun_intensity = 0.6;
    o.ambient_intensity = 0.3;
    o.sky_zenith_colour = {0.45, 0.5, 0.65};
    o.sky_horizon_colour = {0.9, 0.75, 0.55};
    o.cloud_cover = 0.7;
    o.visibility_m = 3000.0;
    o.exposure_gain = 0.8;
  }
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
  f << text;
  f.close();
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
}

// The airframe named by --airframe (procedural with the seed, or a mesh file), its name and bounding radius into `r`.
sim::DroneSpec airframe_spec(const std::string& airframe, uint64_t seed, const DatasetSynthConfig& synth,
                             ScenarioRandomResult& r) {
  sim::DroneSpec spec;
  if (airframe == "quad" || airframe == "hex" || airframe == "octo") {
    SynthRandom rng(seed, kAirframeStream, 0);
    spec = random_airframe(synth, rng, airframe);
    r.airframe = "procedural " + airframe;
  } else {
    if (!fs::is_regular_file(airframe))
      throw std::invalid_argument("--airframe = '" + airframe + "': not quad, hex, octo nor a mesh file");
    spec.frame = "mesh";
    spec.mesh_path = fs::absolute(airframe).lexically_normal().string();
    r.airframe = fs::path(airframe).filename().string();
  }
  r.bounding_radius_m = sim::DroneModel::from_spec(spec).bounding_radius();
  return spec;
}

// The localizer's and the renderer's files of a written scenario (FILE.localizer.yaml, FILE.render.yaml).
void write_localizer_and_render(const ScenarioRandomResult& r, const std::string& header, uint64_t seed,
                                const std::string& lighting, const DatasetSynthConfig& synth) {
  LocalizerTarget target;
  target.radius_m = r.bounding_radius_m;
  target.min_range_m = std::max(target.min_range_m, 1.5 * r.bounding_radius_m);
  write_file(r.localizer_path, common::print_options(target, header + " (the localizer's defaults otherwise)"));
  RenderSection render;
  SynthRandom scene_rng(seed, kSceneStream, 0);
  render.render = random_scene(synth, scene_rng);  // ground, treeline, clouds as dataset synth draws them
  apply_lighting(lighting, render.render);
  write_file(r.render_path, common::print_options(render, header + ": lighting " + lighting));
}

}  // namespace

std::vector<std::string> ScenarioRandomOptions::validate() const {
  std::vector<std::string> p;
  if (view != "behind" && view != "side") p.push_back("--view = '" + view + "': must be behind or side");
  if (lighting != "A" && lighting != "B") p.push_back("--lighting = '" + lighting + "': must be A or B");
  if (out.empty()) p.push_back("--out: required (the scenario file to write, e.g. build/suite/flight.yaml)");
  if (!out.empty() && fs::path(out).extension() != ".yaml") p.push_back("--out = '" + out + "': must end in .yaml");
  if (airframe.empty()) p.push_back("--airframe: must be quad, hex, octo or a mesh file");
  const auto range = [&](const char* lo_key, double lo, const char* hi_key, double hi, double floor) {
    if (!(lo >= floor && hi >= lo && std::isfinite(hi)))
      p.push_back(fmt::format("{} = {}, {} = {}: need {} <= {} <= {}", lo_key, lo, hi_key, hi, floor, lo_key, hi_key));
  };
  range("duration_min_s", duration_min_s, "duration_max_s", duration_max_s, 1.0);
  range("speed_min_mps", speed_min_mps, "speed_max_mps", speed_max_mps, 0.01);
  range("offset_min_m", offset_min_m, "offset_max_m", offset_max_m, 1.0);
  range("altitude_min_m", altitude_min_m, "altitude_max_m", altitude_max_m, 1.0);
  range("leg_min_m", leg_min_m, "leg_max_m", leg_max_m, 0.1);
  if (!(offset_elevation_max_deg >= 0.0 && offset_elevation_max_deg <= 25.0))
    p.push_back(common::problem("offset_elevation_max_deg", offset_elevation_max_deg, "must be in [0, 25]"));
  if (!(climb_max >= 0.0 && climb_max <= 1.0))
    p.push_back(common::problem("climb_max", climb_max, "must be in [0, 1]"));
  if (!(accel_mps2 > 0.0 && accel_mps2 <= 4.0))
    p.push_back(common::problem("accel_mps2", accel_mps2, "must be in (0, 4]"));
  return p;
}

std::string ScenarioRandomResult::one_line() const {
  return fmt::format("wrote {} ({:.1f} s, {} legs, {}, offset {:.1f} m, bounding radius {:.3f} m) and its configs",
                     scenario_path, duration_s, legs, airframe, offset_in_world.norm(), bounding_radius_m);
}

ScenarioRandomResult write_random_scenario(const ScenarioRandomOptions& o) {
  if (const auto problems = o.validate(); !problems.empty())
    throw std::invalid_argument(fmt::format("{}", fmt::join(problems, "; ")));
  ScenarioRandomResult r;
  const DatasetSynthConfig synth;  // the ranges `wingman dataset synth` draws airframes and scenes from

  // The leader's airframe and its bounding radius (propellers spinning), as the simulator computes and reports it.
  sim::DroneSpec spec = airframe_spec(o.airframe, o.seed, synth, r);

  // The formation offset, and the headings that give the view.
  SynthRandom rng(o.seed, kPathStream, 0);
  r.duration_s = std::round(rng.uniform(o.duration_min_s, o.duration_max_s) * 10.0) / 10.0;
  const double distance = rng.uniform(o.offset_min_m, o.offset_max_m);
  const double bearing = rng.uniform(-kSynthPi, kSynthPi);
  const double elevation = rng.uniform(-o.offset_elevation_max_deg, o.offset_elevation_max_deg) * kSynthDeg;
  r.offset_in_world = distance * Eigen::Vector3d(std::cos(elevation) * std::cos(bearing),
                                                 std::cos(elevation) * std::sin(bearing), std::sin(elevation));
  const double yaw_to_leader = std::atan2(-r.offset_in_world.y(), -r.offset_in_world.x());  // the camera's heading
  const double side = rng.chance(0.5) ? 1.0 : -1.0;
  const double leader_yaw = o.view == "behind" ? yaw_to_leader : yaw_to_leader + side * 0.5 * kSynthPi;
  const double floor_z = o.altitude_min_m + std::max(0.0, -r.offset_in_world.z());  // the follower stays above 1 m
  const Eigen::Vector3d p_leader(0.0, 0.0, rng.uniform(std::max(floor_z, o.altitude_min_m), o.altitude_max_m));
  const Eigen::Vector3d p_follower = p_leader + r.offset_in_world;

  // The leader's path: legs from rest to rest until the flight's duration is covered.
  std::string waypoints;
  Eigen::Vector3d p = p_leader;
  for (double t = 0.0; t < r.duration_s;) {
    const double heading = rng.uniform(-kSynthPi, kSynthPi);
    const double length = rng.uniform(o.leg_min_m, o.leg_max_m);
    double dz = rng.uniform(-o.climb_max, o.climb_max) * length;
    dz = std::clamp(p.z() + dz, std::max(floor_z, o.altitude_min_m), o.altitude_max_m) - p.z();
    const Eigen::Vector3d next = p + Eigen::Vector3d(length * std::cos(heading), length * std::sin(heading), dz);
    const double speed = std::round(rng.uniform(o.speed_min_mps, o.speed_max_mps) * 100.0) / 100.0;
    const double stop = rng.chance(0.3) ? std::round(rng.uniform(0.5, 3.0) * 10.0) / 10.0 : 0.0;
    t += leg_time_s((next - p).norm(), speed, o.accel_mps2) + stop;
    waypoints += fmt::format("        - {{position: {}, speed: {:.2f}, stop_s: {:.1f}}}\n", vec(next), speed, stop);
    p = next;
    ++r.legs;
  }

  const fs::path out(o.out);
  const std::string stem = (out.parent_path() / out.stem()).string();
  r.scenario_path = o.out;
  r.localizer_path = stem + ".localizer.yaml";
  r.follower_path = stem + ".follower_ctrl.yaml";
  r.render_path = stem + ".render.yaml";
  r.json_path = stem + ".json";
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());

  const std::string command =
      fmt::format("wingman scenario random --seed {} --airframe {} --view {} --lighting {}", o.seed,
                  spec.frame == "mesh" ? spec.mesh_path : o.airframe, o.view, o.lighting);
  YamlSpecWriter drone("      ");
  spec.visit(drone, "");
  std::string yaml = fmt::format(
      "# Written by `{}`: an out-of-sample formation flight (tools/experiment.sh suite). Keys: docs/simulation.md.\n"
      "# Fly it with its configs: tools/fly.sh --scenario {} --localizer-config {} --follower-config {} "
      "--render-config {}\n",
      command, out.filename().string(), fs::path(r.localizer_path).filename().string(),
      fs::path(r.follower_path).filename().string(), fs::path(r.render_path).filename().string());
  yaml += fmt::format("name: {}\n", out.stem().string());
  yaml += fmt::format(
      "description: \"seed {}: {} leader seen {}, lighting {}; formation offset {:.1f} m; {} legs at 0.3-3 m/s\"\n",
      o.seed, r.airframe, o.view == "behind" ? "from behind" : "side-on", o.lighting, distance, r.legs);
  yaml += "start_utime: 1767225600000000\n";
  yaml += fmt::format("duration_s: {:.1f}\ncommand_delay_s: 0.1\nseed: {}\n\nvehicles:\n", r.duration_s, o.seed);
  yaml += fmt::format(
      "  - name: follower\n    id: 0\n    control: setpoints\n    initial:\n      position: {}\n      yaw_deg: "
      "{:.3f}\n\n",
      vec(p_follower), yaw_to_leader / kSynthDeg);
  yaml += fmt::format(
      "  - name: leader\n    id: 1\n    control: script\n    initial:\n      position: {}\n"
      "      yaw_deg: {:.3f}\n    drone:\n{}",
      vec(p_leader), leader_yaw / kSynthDeg, drone.str());
  yaml += fmt::format("    dynamics:\n      max_speed_xy: {:.2f}\n      max_accel_xy: {:.2f}\n", o.speed_max_mps + 1.0,
                      std::max(2.0, 2.0 * o.accel_mps2));
  yaml += fmt::format("    motion:\n      type: waypoints\n      accel: {:.2f}\n      waypoints:\n{}", o.accel_mps2,
                      waypoints);
  write_file(r.scenario_path, yaml);

  const std::string header = "written by `" + command + "` for " + out.filename().string();
  write_localizer_and_render(r, header, o.seed, o.lighting, synth);
  FollowerFormation formation;
  formation.offset_m = {r.offset_in_world.x(), r.offset_in_world.y(), r.offset_in_world.z()};
  write_file(r.follower_path, common::print_options(formation, header + " (the follower's defaults otherwise)"));

  // What was drawn, for the suite's table (tools/experiment_summary.py suite).
  common::Json drawn;
  drawn["seed"] = o.seed;
  drawn["airframe"] = r.airframe;
  drawn["view"] = o.view;
  drawn["lighting"] = o.lighting;
  drawn["duration_s"] = r.duration_s;
  drawn["legs"] = r.legs;
  drawn["offset_m"] = {r.offset_in_world.x(), r.offset_in_world.y(), r.offset_in_world.z()};
  drawn["offset_distance_m"] = r.offset_in_world.norm();
  drawn["bounding_radius_m"] = r.bounding_radius_m;
  write_file(r.json_path, common::json_text(drawn) + "\n");

  // What was written loads with the readers that will use it.
  sim::load_scenario(r.scenario_path);
  common::load_options<LocalizerTarget>(r.localizer_path);
  common::load_options<FollowerFormation>(r.follower_path);
  common::load_options<RenderSection>(r.render_path);
  return r;
}

std::vector<std::string> ScenarioSweepOptions::validate() const {
  std::vector<std::string> p;
  if (view != "behind" && view != "side") p.push_back("--view = '" + view + "': must be behind or side");
  if (lighting != "A" && lighting != "B") p.push_back("--lighting = '" + lighting + "': must be A or B");
  if (out.empty()) p.push_back("--out: required (the scenario file to write, e.g. build/suite/sweep.yaml)");
  if (!out.empty() && fs::path(out).extension() != ".yaml") p.push_back("--out = '" + out + "': must end in .yaml");
  if (airframe.empty()) p.push_back("--airframe: must be quad, hex, octo or a mesh file");
  if (!(from_m > 0.0 && std::isfinite(from_m))) p.push_back(common::problem("--from", from_m, "must be > 0 m"));
  if (!(to_m >= from_m && std::isfinite(to_m))) p.push_back(common::problem("--to", to_m, "must be >= --from"));
  if (!(step_m > 0.0 && std::isfinite(step_m))) {
    p.push_back(common::problem("--step", step_m, "must be > 0 m"));
  } else if (to_m >= from_m && std::isfinite(to_m) && (to_m - from_m) / step_m > 1000.0) {
    p.push_back(common::problem("--step", step_m, "gives more than 1000 steps from --from to --to"));
  }
  if (frames_per_step < 1 || frames_per_step > 1000)
    p.push_back(common::problem("--frames-per-step", frames_per_step, "must be in [1, 1000]"));
  if (!(height_m >= 1.0 && height_m <= 1000.0))
    p.push_back(common::problem("height_m", height_m, "must be in [1, 1000] m"));
  return p;
}

ScenarioRandomResult write_sweep_scenario(const ScenarioSweepOptions& o) {
  if (const auto problems = o.validate(); !problems.empty())
    throw std::invalid_argument(fmt::format("{}", fmt::join(problems, "; ")));
  ScenarioRandomResult r;
  const DatasetSynthConfig synth;
  sim::DroneSpec spec = airframe_spec(o.airframe, o.seed, synth, r);
  if (!(o.from_m > 1.5 * r.bounding_radius_m))
    throw std::invalid_argument(fmt::format("--from = {}: must exceed 1.5 x the airframe's bounding radius ({:.3f} m)",
                                            o.from_m, r.bounding_radius_m));
  // Positions (teleport_steps' `steps`): from, from + step, ... up to to (a last partial step is left out).
  r.legs = 1 + static_cast<int>(std::floor((o.to_m - o.from_m) / o.step_m + 1e-9));
  // The camera looks along +Y at the target at the origin's column; the target faces away (behind: its heading +Y,
  // its rear to the camera) or across (side: heading +X, its left side to the camera).
  const Eigen::Vector3d p_target(0.0, 0.0, o.height_m);
  const Eigen::Vector3d p_camera(0.0, -o.from_m, o.height_m);
  r.offset_in_world = p_camera - p_target;
  const double camera_fps = 30.0;  // wingman-sim's default camera.rate_hz: the scenario's length in frames
  r.duration_s = std::ceil(r.legs * o.frames_per_step / camera_fps * 10.0) / 10.0;

  const fs::path out(o.out);
  const std::string stem = (out.parent_path() / out.stem()).string();
  r.scenario_path = o.out;
  r.localizer_path = stem + ".localizer.yaml";
  r.render_path = stem + ".render.yaml";
  r.json_path = stem + ".json";
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  const std::string command = fmt::format(
      "wingman scenario sweep --airframe {} --seed {} --view {} --lighting {} --from {} --to {} --step {} "
      "--frames-per-step {}",
      spec.frame == "mesh" ? spec.mesh_path : o.airframe, o.seed, o.view, o.lighting, o.from_m, o.to_m, o.step_m,
      o.frames_per_step);
  YamlSpecWriter drone("      ");
  spec.visit(drone, "");
  std::string yaml = fmt::format(
      "# Written by `{}`: a range sweep (tools/experiment.sh suite). Keys: docs/simulation.md.\n"
      "# Fly it with its configs: tools/fly.sh --scenario {} --localizer-config {} --render-config {}\n",
      command, out.filename().string(), fs::path(r.localizer_path).filename().string(),
      fs::path(r.render_path).filename().string());
  yaml += fmt::format("name: {}\n", out.stem().string());
  yaml += fmt::format(
      "description: \"{} hovering, seen {}, lighting {}; camera from {} m to {} m in {} m steps, {} frames each\"\n",
      r.airframe, o.view == "behind" ? "from behind" : "side-on", o.lighting, o.from_m, o.to_m, o.step_m,
      o.frames_per_step);
  yaml += "start_utime: 1767225600000000\nduration_s: 0\ncommand_delay_s: 0.1\n";
  yaml += fmt::format("seed: {}\n\nvehicles:\n", o.seed);
  yaml += fmt::format(
      "  - name: camera\n    id: 0\n    control: script\n    initial:\n      position: {}\n      yaw_deg: 90\n"
      "    motion:\n      type: teleport_steps\n      step: [0, {:.6g}, 0]\n      steps: {}\n      frames_per_step: "
      "{}\n\n",
      vec(p_camera), -o.step_m, r.legs, o.frames_per_step);
  yaml += fmt::format(
      "  - name: target\n    id: 1\n    control: script\n    initial:\n      position: {}\n      yaw_deg: {}\n"
      "    drone:\n{}    motion:\n      type: hover\n",
      vec(p_target), o.view == "behind" ? 90 : 0, drone.str());
  write_file(r.scenario_path, yaml);
  const std::string header = "written by `" + command + "` for " + out.filename().string();
  write_localizer_and_render(r, header, o.seed, o.lighting, synth);
  common::Json drawn;
  drawn["kind"] = "sweep";
  drawn["seed"] = o.seed;
  drawn["airframe"] = r.airframe;
  drawn["view"] = o.view;
  drawn["lighting"] = o.lighting;
  drawn["from_m"] = o.from_m;
  drawn["to_m"] = o.to_m;
  drawn["step_m"] = o.step_m;
  drawn["steps"] = r.legs;
  drawn["frames_per_step"] = o.frames_per_step;
  drawn["bounding_radius_m"] = r.bounding_radius_m;
  write_file(r.json_path, common::json_text(drawn) + "\n");
  sim::load_scenario(r.scenario_path);
  common::load_options<LocalizerTarget>(r.localizer_path);
  common::load_options<RenderSection>(r.render_path);
  return r;
}

namespace {

// `wingman scenario get FILE KEY`: one top-level value of a scenario, read with the simulator's loader (scripts ask
// for it instead of reading the YAML as text).
std::string scenario_value(const std::string& path, const std::string& key) {
  const sim::Scenario s = sim::load_scenario(path);  // every problem of the file at once
  if (key == "name") return s.name;
  if (key == "description") return s.description;
  if (key == "start_utime") return std::to_string(s.start_utime);
  if (key == "duration_s") return fmt::format("{}", s.duration_s);
  if (key == "command_delay_s") return fmt::format("{}", s.command_delay_s);
  if (key == "seed") return std::to_string(s.seed);
  throw common::ConfigError(fmt::format(
      "{}: no top-level key '{}' to get (name, description, start_utime, duration_s, command_delay_s or seed)", path,
      key));
}

}  // namespace

namespace {

/// `wingman scenario random`'s options as keys (the seed as an int64_t: the loader's integer).
struct RandomVerbOptions {
  ScenarioRandomOptions random;
  int64_t seed = static_cast<int64_t>(ScenarioRandomOptions{}.seed);

  template <class V>
  void visit(V& v) {
    v("flight.seed", seed, "everything random (path, offset, airframe, scene) follows from it");
    v("flight.airframe", random.airframe, "quad, hex or octo (procedural) or a mesh file");
    v("flight.view", random.view, "behind (the leader's rear faces the camera) or side");
    v("flight.lighting", random.lighting, "A (midday, clear) or B (evening, low sun, haze)");
    v("random.duration_min_s", random.duration_min_s, "flight length drawn in [min, max], s");
    v("random.duration_max_s", random.duration_max_s, "the range's upper end");
    v("random.speed_min_mps", random.speed_min_mps, "each leg's cruise speed drawn in [min, max], m/s");
    v("random.speed_max_mps", random.speed_max_mps, "the range's upper end");
    v("random.offset_min_m", random.offset_min_m, "follower-to-leader distance drawn in [min, max], m");
    v("random.offset_max_m", random.offset_max_m, "the range's upper end");
    v("random.offset_elevation_max_deg", random.offset_elevation_max_deg,
      "the follower within +-this above or below the leader, degrees");
    v("random.altitude_min_m", random.altitude_min_m, "the leader's height stays in [min, max], m");
    v("random.altitude_max_m", random.altitude_max_m, "the range's upper end");
    v("random.leg_min_m", random.leg_min_m, "horizontal length of each leg of the leader's path in [min, max], m");
    v("random.leg_max_m", random.leg_max_m, "the range's upper end");
    v("random.climb_max", random.climb_max, "a leg climbs or descends by up to this fraction of its length");
    v("random.accel_mps2", random.accel_mps2, "the leader's acceleration at the ends of each leg, m/s^2");
    v("output.scenario", random.out, "the scenario file to write, FILE.yaml (its configs beside it)");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p =
        named_by_key(random.validate(), {{"--view", "flight.view"},
                                         {"--lighting", "flight.lighting"},
                                         {"--airframe", "flight.airframe"},
                                         {"--out", "output.scenario"},
                                         {"duration_min_s", "random.duration_min_s"},
                                         {"speed_min_mps", "random.speed_min_mps"},
                                         {"offset_min_m", "random.offset_min_m"},
                                         {"altitude_min_m", "random.altitude_min_m"},
                                         {"leg_min_m", "random.leg_min_m"},
                                         {"offset_elevation_max_deg", "random.offset_elevation_max_deg"},
                                         {"climb_max", "random.climb_max"},
                                         {"accel_mps2", "random.accel_mps2"}});
    if (seed < 0) p.push_back(common::problem("flight.seed", static_cast<double>(seed), "must be >= 0"));
    return p;
  }
  ScenarioRandomOptions options() const {
    ScenarioRandomOptions o = random;
    o.seed = static_cast<uint64_t>(seed);
    return o;
  }
};

/// `wingman scenario sweep`'s options as keys.
struct SweepVerbOptions {
  ScenarioSweepOptions sweep;
  int64_t seed = static_cast<int64_t>(ScenarioSweepOptions{}.seed);

  template <class V>
  void visit(V& v) {
    v("sweep.airframe", sweep.airframe, "quad, hex or octo (procedural, drawn with sweep.seed) or a mesh file");
    v("sweep.seed", seed, "seed of a procedural airframe, the scene and the image noise");
    v("sweep.view", sweep.view, "behind (the rear faces the camera) or side");
    v("sweep.lighting", sweep.lighting, "A (midday) or B (evening)");
    v("sweep.from_m", sweep.from_m, "first distance, camera to the target's centre, m");
    v("sweep.to_m", sweep.to_m, "last distance, m");
    v("sweep.step_m", sweep.step_m, "distance added at each step, m");
    v("sweep.frames_per_step", sweep.frames_per_step, "frames at each distance");
    v("sweep.height_m", sweep.height_m, "both vehicles at this height (the target seen level), m");
    v("output.scenario", sweep.out, "the scenario file to write, FILE.yaml (its configs beside it)");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p = named_by_key(sweep.validate(), {{"--view", "sweep.view"},
                                                                 {"--lighting", "sweep.lighting"},
                                                                 {"--airframe", "sweep.airframe"},
                                                                 {"--out", "output.scenario"},
                                                                 {"--from", "sweep.from_m"},
                                                                 {"--to", "sweep.to_m"},
                                                                 {"--step", "sweep.step_m"},
                                                                 {"--frames-per-step", "sweep.frames_per_step"},
                                                                 {"height_m", "sweep.height_m"}});
    if (seed < 0) p.push_back(common::problem("sweep.seed", static_cast<double>(seed), "must be >= 0"));
    return p;
  }
  ScenarioSweepOptions options() const {
    ScenarioSweepOptions o = sweep;
    o.seed = static_cast<uint64_t>(seed);
    return o;
  }
};

}  // namespace

struct ScenarioVerbs::State {
  CLI::App* random = nullptr;
  CLI::App* sweep = nullptr;
  CLI::App* get = nullptr;
  std::string get_file, get_key;
  CLI::App* set = nullptr;
  ScenarioSetOptions set_options;
  ScenarioRandomOptions options;       // what the flags say; random runs with what its layers load
  ScenarioSweepOptions sweep_options;  // likewise
  std::unique_ptr<VerbLayers> random_layers, sweep_layers;
};

ScenarioVerbs::ScenarioVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  CLI::App* scenario = app.add_subcommand(
      "scenario", "Simulation scenarios: random out-of-sample formation flights, range sweeps, a scenario's values");
  scenario->require_subcommand(1);
  ScenarioRandomOptions& o = s_->options;
  s_->random = scenario->add_subcommand(
      "random",
      "Write a seeded random formation flight for wingman-sim (leader on a random 3-D path at 0.3-3 m/s for 30-60 s, "
      "follower 4-20 m away) and, beside it, FILE.localizer.yaml (the leader's bounding radius), "
      "FILE.follower_ctrl.yaml (the formation offset) and FILE.render.yaml (lighting) for tools/fly.sh");
  s_->random->add_option("--seed", o.seed, "Seed: the same seed gives the same files")->required();
  s_->random->add_option("--airframe", o.airframe,
                         "quad, hex or octo (procedural, drawn as dataset synth draws them) or a mesh file, e.g. "
                         "../shared/meshes/holybro_x500v2.glb");
  s_->random->add_option("--view", o.view, "behind (the leader's rear faces the camera) or side");
  s_->random->add_option("--lighting", o.lighting, "A (midday, clear) or B (evening, low sun, haze)");
  s_->random->add_option("--out", o.out, "The scenario file to write, FILE.yaml")->required();
  s_->random_layers = std::make_unique<VerbLayers>(s_->random);
  s_->random_layers->keys({
      {"--seed", "flight.seed", false},
      {"--airframe", "flight.airframe", true},
      {"--view", "flight.view", true},
      {"--lighting", "flight.lighting", true},
      {"--out", "output.scenario", true},
  });

  ScenarioSweepOptions& w = s_->sweep_options;
  s_->sweep = scenario->add_subcommand(
      "sweep",
      "Write a range sweep for wingman-sim: the airframe hovers, the camera steps away from it along the line of "
      "sight (--from to --to in --step, --frames-per-step frames each), and beside it FILE.localizer.yaml (the "
      "airframe's bounding radius), FILE.render.yaml (lighting) and FILE.json for tools/fly.sh");
  s_->sweep->add_option("--airframe", w.airframe, "quad, hex or octo (procedural, drawn with --seed) or a mesh file");
  s_->sweep->add_option("--seed", w.seed, "Seed of a procedural airframe, the scene and the image noise");
  s_->sweep->add_option("--view", w.view, "behind (the rear faces the camera) or side");
  s_->sweep->add_option("--lighting", w.lighting, "A (midday) or B (evening)");
  s_->sweep->add_option("--from", w.from_m, "First distance, m");
  s_->sweep->add_option("--to", w.to_m, "Last distance, m");
  s_->sweep->add_option("--step", w.step_m, "Step, m");
  s_->sweep->add_option("--frames-per-step", w.frames_per_step, "Frames at each distance");
  s_->sweep->add_option("--out", w.out, "The scenario file to write, FILE.yaml")->required();
  s_->sweep_layers = std::make_unique<VerbLayers>(s_->sweep);
  s_->sweep_layers->keys({
      {"--airframe", "sweep.airframe", true},
      {"--seed", "sweep.seed", false},
      {"--view", "sweep.view", true},
      {"--lighting", "sweep.lighting", true},
      {"--from", "sweep.from_m", false},
      {"--to", "sweep.to_m", false},
      {"--step", "sweep.step_m", false},
      {"--frames-per-step", "sweep.frames_per_step", false},
      {"--out", "output.scenario", true},
  });

  s_->get = scenario->add_subcommand(
      "get", "Print one top-level value of a scenario file, read (and checked) with wingman-sim's scenario loader");
  s_->get->add_option("file", s_->get_file, "The scenario file")->required();
  s_->get->add_option("key", s_->get_key, "name, description, start_utime, duration_s, command_delay_s or seed")
      ->required();

  ScenarioSetOptions& c = s_->set_options;
  s_->set = scenario->add_subcommand(
      "set", "Write a copy of a scenario with keys replaced, read back with wingman-sim's scenario loader");
  s_->set->add_option("file", c.file, "The scenario file to copy")->required();
  s_->set
      ->add_option("--set", c.sets,
                   "KEY=VALUE, repeatable, in order: KEY a dotted path, a vehicle named by its name (seed=7, "
                   "vehicles.camera.motion.frames_per_step=2, vehicles.target.initial.position=[0,-10,5]); VALUE "
                   "a YAML scalar or flow sequence")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  s_->set->add_option("--out", c.out, "The copy to write")->required();
}

ScenarioVerbs::~ScenarioVerbs() = default;

int ScenarioVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  if (*s_->set) {
    return run_verb("wingman scenario set", err, [&] {
      write_scenario_copy(s_->set_options);
      out << "wrote " << s_->set_options.out << std::endl;
      return 0;
    });
  }
  if (*s_->get) {
    return run_verb("wingman scenario get", err, [&] {
      out << scenario_value(s_->get_file, s_->get_key) << std::endl;
      return 0;
    });
  }
  if (*s_->sweep) {
    int rc = -1;
    const auto o = s_->sweep_layers->load_or_exit<SweepVerbOptions>(out, err, &rc);
    if (!o) return rc;
    return run_verb("wingman scenario sweep", err, [&] {
      const ScenarioRandomResult r = write_sweep_scenario(o->options());
      out << fmt::format("wrote {} ({} steps, {}, bounding radius {:.3f} m) and its configs", r.scenario_path, r.legs,
                         r.airframe, r.bounding_radius_m)
          << std::endl;
      return 0;
    });
  }
  if (!*s_->random) return -1;
  int rc = -1;
  const auto o = s_->random_layers->load_or_exit<RandomVerbOptions>(out, err, &rc);
  if (!o) return rc;
  return run_verb("wingman scenario random", err, [&] {
    out << write_random_scenario(o->options()).one_line() << std::endl;
    return 0;
  });
}

}  // namespace wingman::tools
