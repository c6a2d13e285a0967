// SPDX-License-Identifier: MIT
// Scripted motion of a simulated vehicle: hover, random walk along a segment, waypoints, teleport steps.
#pragma once

#include "wingman/sim/frame_clock.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace wingman::sim {

/// One waypoint of a `waypoints` script.
struct Waypoint {
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();  ///< position to reach, metres, ENU
  double speed = 0.5;                                    ///< cruise speed on the leg that ends here, m/s, > 0
  double stop_s = 0.0;                                   ///< time to stay here after arriving, s, >= 0
  std::optional<double> yaw_rad;  ///< heading on the leg that ends here; unset = keep the previous one
};

/// What a script does (scenario keys `vehicles[i].motion.*`; docs/simulation.md lists them per type).
struct MotionSpec {
  enum class Type {
    kHover,          ///< hold the initial pose
    kRandomWalk,     ///< fly to random points of a segment and pause, forever (the thesis's 1-D experiment)
    kWaypoints,      ///< fly straight legs between waypoints at their speeds, stopping where asked
    kTeleportSteps,  ///< jump by `step` every `frames_per_step` frames, at rest in between (the static sweep)
  };
  Type type = Type::kHover;

  // kRandomWalk: the walk moves on the segment [segment_from, segment_to] (the initial position must lie on it).
  Eigen::Vector3d segment_from = Eigen::Vector3d::Zero();  ///< one end of the segment, metres, ENU
  Eigen::Vector3d segment_to = Eigen::Vector3d::Zero();    ///< the other end, metres, ENU
  double max_speed = 0.5;    ///< cruise speed of each leg drawn uniformly in [min_speed, max_speed], m/s
  double min_speed = 0.5;    ///< m/s, 0 < min_speed <= max_speed
  double max_pause_s = 0.0;  ///< pause after each leg drawn uniformly in [0, max_pause_s], s
  uint64_t seed = 1;         ///< random seed of the walk

  // kRandomWalk and kWaypoints: acceleration of the reference at the start and end of each leg (trapezoidal
  // speed profile), m/s^2, > 0.
  double accel = 0.5;

  // kWaypoints.
  std::vector<Waypoint> waypoints;  ///< at least one; the first leg starts at the initial position
  bool loop = false;                ///< after the last waypoint fly back to the first and repeat, forever

  // kTeleportSteps: position i (i = 0 .. steps-1) = initial + i * step, held for frames_per_step frames.
  Eigen::Vector3d step = Eigen::Vector3d::Zero();  ///< metres, ENU
  int steps = 1;                                   ///< number of positions, >= 1
  int frames_per_step = 100;                       ///< frames at each position, >= 1
};

/// "hover", "random_walk", "waypoints", "teleport_steps".
const char* motion_type_name(MotionSpec::Type type);

/// The reference a script asks for at one time (world frame ENU).
struct MotionReference {
  Eigen::Vector3d p_in_world = Eigen::Vector3d::Zero();  ///< metres
  Eigen::Vector3d v_in_world = Eigen::Vector3d::Zero();  ///< m/s
  Eigen::Vector3d a_in_world = Eigen::Vector3d::Zero();  ///< m/s^2
  double yaw_rad = 0.0;                                  ///< heading, from east towards north
};

/// A scripted motion (one implementation per MotionSpec::Type). Deterministic: the same spec gives the same
/// reference at the same time, whatever the order of the queries.
class MotionScript {
 public:
  virtual ~MotionScript() = default;
  /// The reference at `t_s` seconds after frame 0 (FrameClock::seconds_since_start), t_s >= 0.
  virtual MotionReference at(double t_s) = 0;
  /// When the script is over (a finite one stays at its last reference), microseconds since epoch; nullopt if it
  /// never ends (hover, random walk, looping waypoints).
  virtual std::optional<int64_t> end_utime() const = 0;
  /// True when the vehicle is placed exactly at the reference (at rest) instead of flying to it.
  virtual bool kinematic() const { return false; }
};

/// Builds the script of `spec` for a vehicle that starts at `p_initial_in_world` (metres, ENU) with heading
/// `yaw_initial_rad`; `clock` gives frame times (teleport steps count frames). Throws std::invalid_argument naming
/// the field (relative to `motion.`) when the spec is invalid, e.g. "min_speed = 2: must be <= max_speed (1)".
std::unique_ptr<MotionScript> make_motion_script(const MotionSpec& spec, const Eigen::Vector3d& p_initial_in_world,
                                                 double yaw_initial_rad, const FrameClock& clock);

/// The problems of `spec` for a vehicle starting at `p_initial_in_world`, one "key = value: rule" line each with
/// keys relative to `motion.` (e.g. "max_speed = -1: must be > 0"); empty when valid.
std::vector<std::string> validate_motion(const MotionSpec& spec, const Eigen::Vector3d& p_initial_in_world);

}  // namespace wingman::sim
