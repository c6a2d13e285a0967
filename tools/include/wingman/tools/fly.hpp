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

/// What `wingman fly` flies: a flight as data. Read from layered files and `--set` (the one loader in common, keys
/// below) with the command line's flags over them; `wingman fly --print-config` shows the result. Relative paths are
/// taken from the working directory (tools/fly.sh runs it from the checkout's root).
struct FlyOptions {
  std::string scenario = "formation_2d";  ///< a file, else the name of `config_dir`/scenarios/NAME.yaml
  std::string out;                        ///< output folder ("" = build/flights/NAME)
  double duration_s = 0.0;                ///< stop after this many simulated seconds (0 = the scenario's length)
  std::string detections = "cnn";         ///< cnn (the detector's model in rendered images) or truth (ground truth)
  std::string render = "auto";            ///< auto (render with cnn, not with truth), on or off
  bool record_images = false;             ///< also record IMAGE_* (2.7 MB per 1280x720 frame)
  std::string truth_box = "sphere";       ///< ground-truth boxes: sphere (the localizer's model) or silhouette
  std::string own_pose_error;             ///< "M,RAD[,TAU]": the own pose's drifting error ("" = none)
  std::string autopilot = "lcm";          ///< lcm (the simulator takes SETPOINT) or mavlink (through wingman-mavlink)
  std::string firmware = "px4";           ///< with mavlink: px4 or ardupilot
  bool zoom_in = false;                   ///< detector: re-detect each box in a full-resolution crop
  bool flip_fusion = false;               ///< detector: also the mirrored frame, boxes fused
  bool coarse_pass = false;               ///< detector: also half the network input, large boxes fused
  std::string model_cfg;                  ///< the detector's network ("" = builtin, or beside model_weights)
  std::string model_weights;              ///< its weights ("" = builtin:wingman-small)
  bool windows = false;                   ///< tracker-driven windows (localizer publishes, detector searches)
  /// A camera rig (geometry/camera_rig.hpp): a file, else `config_dir`/rigs/NAME.yaml; "" = the one forward camera.
  /// With a rig the simulator renders every camera, one detector runs per camera (named detector<camera_id>), and
  /// the localizer fuses them (each takes cameras.rig).
  std::string rig;
  /// With a rig: camera i exposes i x this after its frame's time (the simulator's cameras.stagger_s: cameras not
  /// triggered together), seconds; 0 = every camera at the frame's time.
  double camera_stagger_s = 0.0;
  std::string localizer_config;  ///< "" = config_dir/flights/NAME.localizer.yaml if any, else the defaults
  std::string follower_config;   ///< "" = config_dir/flights/NAME.follower_ctrl.yaml if any, else the defaults
  std::string render_config;     ///< the simulator's render.* keys from this file ("" = its defaults)
  std::vector<std::string> localizer_sets;  ///< KEY=VALUE over the localizer's configuration (its --set)
  std::vector<std::string> follower_sets;   ///< KEY=VALUE over the follower's (its --set; eval measures against it)
  std::vector<std::string> detector_sets;   ///< KEY=VALUE over the detector's (its --set, after the flight's own)
  std::string config_dir = "config";        ///< the checkout's config/ (scenarios, flights, mavlink_bridge.sim.yaml)
  std::string bin_dir;                      ///< the executables ("" = the folder of the running wingman)
  std::string lcm_url;                      ///< the bus ("" = $WINGMAN_LCM_URL, set by tools/netns_run.sh)

  template <class V>
  void visit(V& v) {
    v("flight.scenario", scenario, "config/scenarios/NAME.yaml (under run.config_dir) or a scenario file");
    v("flight.out", out, "output folder; \"\" = build/flights/NAME");
    v("flight.duration_s", duration_s, "simulated seconds to fly; 0 = the scenario's own length");
    v("flight.detections", detections, "cnn (the detector's model in rendered images) or truth (ground truth)");
    v("flight.render", render, "auto (with cnn), on or off");
    v("flight.record_images", record_images, "also record the camera images (2.7 MB a 1280x720 frame)");
    v("flight.truth_box", truth_box, "ground-truth boxes: sphere (the localizer's model) or silhouette");
    v("flight.own_pose_error", own_pose_error, "M,RAD[,TAU]: the reported pose's drifting error; \"\" = exact");
    v("autopilot.kind", autopilot, "lcm (SETPOINT/OWN_POSE) or mavlink (the simulator as a MAVLink vehicle)");
    v("autopilot.firmware", firmware, "with mavlink: px4 or ardupilot");
    v("detector.zoom_in", zoom_in, "re-detect each box in a full-resolution crop");
    v("detector.flip_fusion", flip_fusion, "also detect in the mirrored frame and fuse");
    v("detector.coarse_pass", coarse_pass, "also detect at half the network input (close drones)");
    v("detector.model_cfg", model_cfg, "the network; \"\" = beside model_weights, or the built-in shipped model");
    v("detector.model_weights", model_weights, "the weights; \"\" = the built-in shipped model");
    v("windows.enabled", windows, "tracker-driven windows (localizer publishes, detector searches)");
    v("cameras.rig", rig,
      "config/rigs/NAME.yaml (under run.config_dir) or a rig file: several cameras, a detector each, fused by the "
      "localizer; \"\" = the one forward camera");
    v("cameras.stagger_s", camera_stagger_s,
      "with a rig: camera i exposes i x this after its frame's time (not triggered together), s; 0 = together");
    v("processes.localizer_config", localizer_config,
      "\"\" = config/flights/NAME.localizer.yaml if any, else the localizer's defaults");
    v("processes.follower_config", follower_config,
      "\"\" = config/flights/NAME.follower_ctrl.yaml if any, else the follower's defaults");
    v("processes.render_config", render_config, "the simulator's render.* keys from this file; \"\" = its defaults");
    v("processes.localizer_set", localizer_sets, "KEY=VALUE over the localizer's configuration (its --set)");
    v("processes.follower_set", follower_sets,
      "KEY=VALUE over the follower's configuration (its --set; the formation error follows it)");
    v("processes.detector_set", detector_sets, "KEY=VALUE over the detector's configuration (its --set)");
    v("run.config_dir", config_dir, "the checkout's config folder (scenarios, flights, MAVLink bridge)");
    v("run.bin_dir", bin_dir, "the executables; \"\" = the folder of this wingman");
    v("run.lcm_url", lcm_url, "the LCM bus; \"\" = $WINGMAN_LCM_URL (tools/netns_run.sh sets it)");
  }
  /// Every problem with the values alone, one line each ("flight.detections = 'x': must be cnn or truth").
  std::vector<std::string> validate() const;
};

/// The rig file `rig` names: itself when it is a file, else `config_dir`/rigs/RIG.yaml (not checked to exist).
std::string rig_file(const std::string& rig, const std::string& config_dir);

/// Everything a flight runs, decided before anything starts (so a bad option fails before a process runs).
struct FlightPlan {
  std::string name;                             ///< the scenario's name (its file's stem)
  std::string scenario_file;                    ///< absolute
  std::string rig_file;                         ///< absolute; "" = the one forward camera
  std::string out_dir;                          ///< absolute
  std::string log_path;                         ///< out_dir/flight.lcmlog
  std::vector<std::string> notes;               ///< what flies, one "fly: ..." line each, printed before the flight
  launcher::ProcessSpec logger;                 ///< lcm-logger
  std::vector<launcher::ProcessSpec> pipeline;  ///< detector, localizer, follower [, wingman-mavlink], in start order
  launcher::ProcessSpec sim_print_config;       ///< the simulator's effective configuration into out_dir/sim.yaml
  launcher::ProcessSpec sim;                    ///< the flight itself; it ends the flight
  EvalOptions eval;                             ///< how the log is scored (formation offset from eval_target)
  FlightTargetSources eval_target;              ///< the follower configuration and scenario eval measures against
};

/// The scenario file `scenario` names: itself when it is a file, else `config_dir`/scenarios/SCENARIO.yaml (not
/// checked to exist). As plan_flight reads flight.scenario.
std::string scenario_file(const std::string& scenario, const std::string& config_dir);

/// The plan for `o`: checks the options, the scenario (read with the simulator's loader for its seed), the
/// executables and the configuration files. Throws std::invalid_argument (or common::ConfigError) naming the option
/// or file and what was expected. Reads files; starts nothing.
FlightPlan plan_flight(const FlyOptions& o);

/// Flies `plan`: starts the logger, the pipeline and the simulator, waits for the simulator (a pipeline process or the
/// logger that ends first fails the flight, named), stops the pipeline and then the logger, and scores the log
/// (`wingman eval`'s table on `out`, its HTML report, JSON and CSV in out_dir). SIGINT/SIGTERM stop the flight cleanly.
/// Returns the exit code: 0, the simulator's code when it failed, 1 when a pipeline process ended early, 130 when
/// interrupted.
int fly(const FlightPlan& plan, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
