// SPDX-License-Identifier: MIT
// `wingman fly`: a simulated flight through the real pipeline, as separate processes on the LCM bus, recorded and
// scored against ground truth.
#pragma once

#include "wingman/launcher/process_group.hpp"
#include "wingman/tools/eval.hpp"
#include "wingman/tools/eval_target.hpp"

#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman fly` flies. Relative paths are taken from the working directory (tools/fly.sh runs it from the
/// checkout's root).
struct FlyOptions {
  std::string scenario = "formation_2d";  ///< a file, else the name of `config_dir`/scenarios/NAME.yaml
  std::string out;                        ///< output folder ("" = build/flights/NAME)
  double duration_s = 0.0;                ///< stop after this many simulated seconds (0 = the scenario's length)
  std::string detections = "cnn";         ///< cnn (the detector's model in rendered images) or truth (ground truth)
  std::string render = "auto";            ///< auto (render with cnn, not with truth), on or off
  bool record_images = false;             ///< also record IMAGE_* (2.7 MB per 1280x720 frame)
  std::string truth_box = "sphere";       ///< ground-truth boxes: sphere (the localizer's model) or silhouette
  bool zoom_in = false;                   ///< detector: re-detect each box in a full-resolution crop
  bool flip_fusion = false;               ///< detector: also the mirrored frame, boxes fused
  bool coarse_pass = false;               ///< detector: also half the network input, large boxes fused
  bool windows = false;                   ///< tracker-driven windows (localizer publishes, detector searches)
  std::string localizer_config;           ///< "" = config_dir/flights/NAME.localizer.yaml if any, else the defaults
  std::string follower_config;            ///< "" = config_dir/flights/NAME.follower_ctrl.yaml if any, else the defaults
  std::string render_config;              ///< the simulator's render.* keys from this file ("" = its defaults)
  std::string autopilot = "lcm";          ///< lcm (the simulator takes SETPOINT) or mavlink (through wingman-mavlink)
  std::string firmware = "px4";           ///< with mavlink: px4 or ardupilot
  std::string own_pose_error;             ///< "M,RAD[,TAU]": the own pose's drifting error ("" = none)
  std::string model_cfg;              ///< the detector's network ("" = builtin:wingman-small, or beside model_weights)
  std::string model_weights;          ///< its weights ("" = builtin:wingman-small)
  std::string config_dir = "config";  ///< the checkout's config/ (scenarios, flights, mavlink_bridge.sim.yaml)
  std::string bin_dir;                ///< the executables ("" = the folder of the running wingman)
  std::string lcm_url;                ///< the bus ("" = $WINGMAN_LCM_URL, set by tools/netns_run.sh)

  /// Every problem with the values alone, one line each ("--detections 'x': expected cnn or truth").
  std::vector<std::string> validate() const;
};

/// Everything a flight runs, decided before anything starts (so a bad option fails before a process runs).
struct FlightPlan {
  std::string name;                             ///< the scenario's name (its file's stem)
  std::string scenario_file;                    ///< absolute
  std::string out_dir;                          ///< absolute
  std::string log_path;                         ///< out_dir/flight.lcmlog
  std::vector<std::string> notes;               ///< what flies, one "fly: ..." line each, printed before the flight
  launcher::ProcessSpec logger;                 ///< lcm-logger
  std::vector<launcher::ProcessSpec> pipeline;  ///< detector, localizer, follower [, wingman-mavlink], in start order
  launcher::ProcessSpec sim_print_config;       ///< the simulator's effective configuration into out_dir/sim.yaml
  launcher::ProcessSpec sim;                    ///< the flight itself; it ends the flight
  EvalOptions eval;                             ///< how the log is scored afterwards
  FlightTargetSources eval_target;              ///< the follower configuration and scenario eval measures against
};

/// The plan for `o`: checks the options, the scenario (read with the simulator's loader for its seed), the
/// executables and the configuration files. Throws std::invalid_argument (or common::ConfigError) naming the option
/// or file and what was expected. Reads files; starts nothing.
FlightPlan plan_flight(const FlyOptions& o);

/// Flies `plan`: starts the logger, the pipeline and the simulator, waits for the simulator (a pipeline process that
/// ends first fails the flight, named), stops the pipeline and then the logger, and scores the log (`wingman eval`'s
/// table on `out`, its HTML report, JSON and CSV in out_dir). SIGINT/SIGTERM stop the flight cleanly. Returns the exit
/// code: 0, the simulator's code when it failed, 1 when a pipeline process ended early, 130 when interrupted.
int fly(const FlightPlan& plan, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
