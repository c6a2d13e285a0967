// SPDX-License-Identifier: MIT
// `wingman scenario random`: a seeded random formation flight for wingman-sim, with the configs fly.sh flies it with.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace wingman::tools {

/// What `wingman scenario random` draws, and within which ranges. The same options give the same files, byte for byte.
struct ScenarioRandomOptions {
  uint64_t seed = 1001;  ///< --seed: everything random (path, offset, airframe, scene) follows from it
  /// --airframe: quad, hex or octo (a procedural airframe drawn as `wingman dataset synth` draws them, arm count
  /// fixed), or a mesh file (.glb, .gltf, .obj, ...; written into the scenario as an absolute path).
  std::string airframe = "quad";
  /// --view: behind (the leader's heading points away from the camera: its rear faces the follower) or side (its
  /// heading is 90 degrees off the line of sight, to the left or right by the seed).
  std::string view = "behind";
  /// --lighting: A (midday: sun 45 degrees high, clear blue sky, exposure 1) or B (evening: sun 8 degrees high in the
  /// west, warm hazy sky, clouds, less light, exposure 0.8). The ground, treeline and clouds vary with the seed.
  std::string lighting = "A";
  std::string out;               ///< --out FILE.yaml: the scenario; the three configs go beside it (see below)
  double duration_min_s = 30.0;  ///< flight length drawn uniformly in [duration_min_s, duration_max_s], s
  double duration_max_s = 60.0;  ///< (30..60 s)
  double speed_min_mps = 0.3;    ///< each leg's cruise speed, uniform in [speed_min_mps, speed_max_mps], m/s
  double speed_max_mps = 3.0;    ///< (0.3..3 m/s)
  double offset_min_m = 4.0;     ///< follower-to-leader distance of the formation, uniform in [min, max], m
  double offset_max_m = 20.0;    ///< (4..20 m)
  double offset_elevation_max_deg = 10.0;  ///< the follower sits within +-this above or below the leader, degrees
  double altitude_min_m = 6.0;             ///< the leader's height stays in [altitude_min_m, altitude_max_m], m
  double altitude_max_m = 18.0;
  double leg_min_m = 3.0;  ///< horizontal length of each leg of the leader's path, uniform in [min, max], m
  double leg_max_m = 12.0;
  double climb_max = 0.3;   ///< a leg climbs or descends by up to this fraction of its horizontal length
  double accel_mps2 = 1.0;  ///< the leader's acceleration at the ends of each leg, m/s^2

  /// Every problem, as "--key = value: rule" (empty when valid).
  std::vector<std::string> validate() const;
};

/// What one run wrote, and the numbers drawn.
struct ScenarioRandomResult {
  std::string scenario_path;  ///< FILE.yaml: the scenario (loads with sim::load_scenario; checked before returning)
  /// FILE.localizer.yaml: target.radius_m = the leader's bounding radius, range.min_m = max(0.5, 1.5 x radius) (it must
  /// exceed the radius; 0.5 is the default), the localizer's defaults otherwise.
  std::string localizer_path;
  std::string follower_path;  ///< FILE.follower_ctrl.yaml: formation.offset_m (and height_mode target)
  std::string render_path;    ///< FILE.render.yaml: render.* for wingman-sim --render-config (lighting, scene)
  std::string json_path;    ///< FILE.json: what was drawn (seed, airframe, view, lighting, offset, radius), one object
  double duration_s = 0.0;  ///< the scenario's duration_s
  double bounding_radius_m = 0.0;                             ///< the leader's, as the simulator reports it
  Eigen::Vector3d offset_in_world = Eigen::Vector3d::Zero();  ///< follower minus leader at the start, ENU, metres
  int legs = 0;                                               ///< waypoints of the leader's path
  std::string airframe;                                       ///< quad, hex, octo or the mesh file's name
  /// "wrote S (seed 1001, quad, behind, lighting A: 42.3 s, 9 legs, offset 11.2 m, bounding radius 0.371 m)".
  std::string one_line() const;
};

/// Draws the flight and writes five files (FILE.yaml and, beside it, FILE.localizer.yaml, FILE.follower_ctrl.yaml,
/// FILE.render.yaml and FILE.json; FILE = --out without .yaml). The scenario:
///  - vehicle 0 `follower` (control setpoints, the default F450-like quad) at the leader's start plus the formation
///    offset (distance in [offset_min_m, offset_max_m], any bearing, elevation within +-offset_elevation_max_deg),
///    facing the leader;
///  - vehicle 1 `leader` with the airframe, at a height in [altitude_min_m, altitude_max_m], flying waypoints: legs of
///    random horizontal direction and length, climbing or descending, each at a cruise speed in
///    [speed_min_mps, speed_max_mps], sometimes with a stop; its heading stays as --view sets it;
///  - duration_s in [duration_min_s, duration_max_s]; seed = --seed (image noise).
/// Throws std::invalid_argument for bad options or an unknown airframe, std::runtime_error naming the file for I/O
/// or mesh problems, sim::ScenarioError if the written scenario does not load (a bug).
ScenarioRandomResult write_random_scenario(const ScenarioRandomOptions& options);

/// What `wingman scenario sweep` writes: a range sweep of one airframe (issue 29's per-airframe sweeps). The target
/// hovers; the camera vehicle (scripted, no setpoints) steps straight away from it along the line of sight.
struct ScenarioSweepOptions {
  /// --airframe: quad, hex or octo (procedural, drawn with --seed as `wingman scenario random` draws them), or a mesh
  /// file (written into the scenario as an absolute path).
  std::string airframe = "quad";
  uint64_t seed = 2001;         ///< --seed: the procedural airframe, the scene and the image noise
  std::string view = "behind";  ///< --view: behind (the target's rear faces the camera) or side (its left side)
  std::string lighting = "A";   ///< --lighting: A or B, as `wingman scenario random`
  double from_m = 3.0;          ///< --from: the first distance, camera to the target's centre, m (> radius)
  double to_m = 30.0;           ///< --to: the last distance, m (>= from)
  double step_m = 0.5;          ///< --step: distance added at each step, m (> 0); at most 1000 steps
  int frames_per_step = 8;      ///< --frames-per-step: frames at each distance (>= 1)
  double height_m = 5.0;        ///< both at this height: the target is seen level, m (>= 1)
  std::string out;              ///< --out FILE.yaml; FILE.localizer.yaml, FILE.render.yaml and FILE.json beside it

  /// Every problem, as "--key = value: rule" (empty when valid).
  std::vector<std::string> validate() const;
};

/// Writes FILE.yaml (the sweep), FILE.localizer.yaml (target.radius_m = the airframe's bounding radius as the
/// simulator reports it, range.min_m = max(0.5, 1.5 x radius); the localizer's defaults otherwise), FILE.render.yaml
/// (lighting, the scene drawn with the seed) and FILE.json (what was written). The result's offset_in_world is the
/// first step's target-minus-camera vector; legs = the number of steps. Throws as write_random_scenario.
ScenarioRandomResult write_sweep_scenario(const ScenarioSweepOptions& options);

/// Adds `scenario random` and `scenario sweep` to the CLI and runs them.
class ScenarioVerbs {
 public:
  explicit ScenarioVerbs(CLI::App& app);
  ~ScenarioVerbs();
  /// After parsing: runs `scenario random` or `scenario sweep` when chosen and returns its exit code (0 ok, 1
  /// failure, 2 bad arguments), or -1 when neither was chosen. The summary goes to `out`, errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
