// SPDX-License-Identifier: MIT
// `wingman fly`: the flight's processes and their command lines (plan_flight), then the flight itself (fly).
#include "wingman/tools/fly.hpp"

#include "wingman/launcher/launch_setup.hpp"
#include "wingman/tools/report.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/camera_rig.hpp>
#include <wingman/sim/scenario.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace wingman::tools {

namespace fs = std::filesystem;
using launcher::process;

namespace {

/// Seconds the pipeline gets to end after SIGTERM before it is killed (its processes end within one second).
constexpr double kPipelineGraceS = 10.0;
/// Seconds the logger keeps recording after the pipeline ended (their last STOPPING heartbeats).
constexpr double kLoggerTailS = 0.3;

const char* bool_text(bool b) { return b ? "true" : "false"; }

/// `path` made absolute with symbolic links resolved as far as it exists (the shell's `realpath`).
std::string absolute(const std::string& path) { return fs::weakly_canonical(fs::absolute(path)).string(); }

bool readable_file(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  return std::ifstream(path).good();
}

/// The own-pose error's --set keys for the simulator from "M,RAD[,TAU]" (the values are checked by its loader).
std::vector<std::string> own_pose_sets(const std::string& spec) {
  std::vector<std::string> parts;
  size_t begin = 0;
  for (;;) {
    const size_t comma = spec.find(',', begin);
    parts.push_back(spec.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  if (parts.size() < 2 || parts.size() > 3 || parts[0].empty() || parts[1].empty() ||
      (parts.size() == 3 && parts[2].empty())) {
    throw std::invalid_argument(fmt::format(
        "flight.own_pose_error (--own-pose-error) = '{}': expected M,RAD or M,RAD,TAU (e.g. 0.3,0.01)", spec));
  }
  return {"--set", "own_pose.position_std_m=" + parts[0],
          "--set", "own_pose.attitude_std_rad=" + parts[1],
          "--set", "own_pose.correlation_time_s=" + (parts.size() == 3 ? parts[2] : std::string("2.0"))};
}

}  // namespace

std::vector<std::string> FlyOptions::validate() const {
  std::vector<std::string> p;
  auto one_of = [&](const char* key, const std::string& value, std::initializer_list<const char*> allowed) {
    std::string list;
    for (const char* a : allowed) {
      if (value == a) return;
      list += (list.empty() ? "" : " or ") + std::string(a);
    }
    p.push_back(common::problem(key, value, "must be " + list));
  };
  one_of("flight.detections", detections, {"cnn", "truth"});
  one_of("flight.render", render, {"auto", "on", "off"});
  one_of("flight.truth_box", truth_box, {"sphere", "silhouette"});
  one_of("autopilot.kind", autopilot, {"lcm", "mavlink"});
  one_of("autopilot.firmware", firmware, {"px4", "ardupilot"});
  if (!(duration_s >= 0.0))
    p.push_back(common::problem("flight.duration_s", duration_s, "must be >= 0 seconds (0: the scenario's)"));
  if (scenario.empty()) p.push_back(common::problem("flight.scenario", scenario, "must name a scenario or a file"));
  if (!(camera_stagger_s >= 0.0) || !std::isfinite(camera_stagger_s))
    p.push_back(common::problem("cameras.stagger_s", camera_stagger_s, "must be >= 0 seconds (0: together)"));
  else if (camera_stagger_s > 0 && rig.empty())
    p.push_back(common::problem("cameras.stagger_s", camera_stagger_s, "needs cameras.rig (--rig)"));
  if (detections == "cnn" && render == "off")
    p.push_back(common::problem("flight.render", render, "cnn detections need images: on or auto"));
  return p;
}

FlightPlan plan_flight(const FlyOptions& o) {
  if (const auto problems = o.validate(); !problems.empty()) {
    std::string all;
    for (const auto& line : problems) all += (all.empty() ? "" : "; ") + line;
    throw std::invalid_argument(all);
  }
  FlightPlan plan;
  // The scenario: a file, else config/scenarios/NAME.yaml (its name: the file's stem, or NAME).
  plan.scenario_file = absolute(scenario_file(o.scenario, o.config_dir));
  plan.name = fs::path(plan.scenario_file).stem().string();
  if (!readable_file(plan.scenario_file))
    throw std::invalid_argument(fmt::format("no scenario '{}' (looked for {})", o.scenario, plan.scenario_file));
  // The box noise follows the scenario's seed (as the rendered noise does), so runs of different seeds differ.
  const uint64_t scenario_seed = sim::load_scenario(plan.scenario_file).seed;  // every problem of the file at once

  // The cameras: one forward camera, or a rig's (read now: every problem of the file before anything starts).
  std::vector<geometry::RigCamera> rig_cameras;
  if (!o.rig.empty()) {
    plan.rig_file = absolute(rig_file(o.rig, o.config_dir));
    if (!readable_file(plan.rig_file))
      throw std::invalid_argument(
          fmt::format("cameras.rig (--rig) = '{}': no such rig (looked for {})", o.rig, plan.rig_file));
    rig_cameras = geometry::load_camera_rig(plan.rig_file).cameras;
  }

  const bool mavlink = o.autopilot == "mavlink";
  std::vector<std::string> exes = {"wingman-sim", "wingman-detector", "wingman-localizer", "wingman-follower-ctrl"};
  if (mavlink) exes.push_back("wingman-mavlink");
  const std::string bin = launcher::executables_dir(o.bin_dir, exes);
  auto exe = [&](const char* name) { return (fs::path(bin) / name).string(); };
  const std::string url = launcher::private_bus_url(o.lcm_url, "wingman fly", "tools/fly.sh");

  // Configuration files given on the command line must be readable; the per-flight ones are used when they exist.
  auto given = [&](const std::string& path, const char* flag) -> std::string {
    if (path.empty()) return "";
    if (!readable_file(path)) throw std::invalid_argument(fmt::format("{} {}: cannot read it", flag, path));
    return absolute(path);
  };
  auto flight_file = [&](const char* process_name) -> std::string {
    const fs::path f = fs::path(o.config_dir) / "flights" / fmt::format("{}.{}.yaml", plan.name, process_name);
    return readable_file(f.string()) ? absolute(f.string()) : "";
  };
  std::string localizer_config = given(o.localizer_config, "processes.localizer_config (--localizer-config)");
  std::string follower_config = given(o.follower_config, "processes.follower_config (--follower-config)");
  const std::string render_config = given(o.render_config, "processes.render_config (--render-config)");
  if (o.localizer_config.empty()) localizer_config = flight_file("localizer");
  if (o.follower_config.empty()) follower_config = flight_file("follower_ctrl");

  plan.out_dir = absolute(o.out.empty() ? (fs::path("build") / "flights" / plan.name).string() : o.out);
  plan.log_path = (fs::path(plan.out_dir) / "flight.lcmlog").string();

  // The CNN: the detector's built-in shipped model unless another is given (its cfg beside its weights by default).
  std::string model_weights = o.model_weights.empty() ? "builtin:wingman-small" : o.model_weights;
  std::string model_cfg = o.model_cfg;
  if (model_cfg.empty() && !o.model_weights.empty()) {
    const std::string stem =
        o.model_weights.size() > 8 && o.model_weights.substr(o.model_weights.size() - 8) == ".weights"
            ? o.model_weights.substr(0, o.model_weights.size() - 8)
            : o.model_weights;
    model_cfg = stem + ".cfg";
    if (!readable_file(model_cfg))
      throw std::invalid_argument(
          fmt::format("detector.model_weights (--model-weights, WINGMAN_MODEL_WEIGHTS) {} has no {} beside it: "
                      "give detector.model_cfg (--model-cfg, WINGMAN_MODEL_CFG)",
                      o.model_weights, model_cfg));
  }
  if (model_cfg.empty()) model_cfg = "builtin:wingman-small";

  const bool cnn = o.detections == "cnn";
  bool render = o.render == "on";
  if (cnn) {
    render = true;
    plan.notes.push_back(
        fmt::format("fly: detections from the CNN ({}, {}) in rendered 1280x720 images", model_cfg, model_weights));
  } else {
    plan.notes.push_back(fmt::format(
        "fly: detections come from the SIMULATOR'S GROUND TRUTH ({} boxes, 1 px edge noise; flagged "
        "source=SOURCE_GROUND_TRUTH in detections, targets and setpoints); the detector process runs without a model",
        o.truth_box));
    if (!render)
      plan.notes.push_back("fly: images are not rendered (ground-truth detections need none; --render renders them)");
  }
  plan.notes.push_back(fmt::format("fly: scenario {}, LCM bus {} (private network namespace), output in {}", plan.name,
                                   url, plan.out_dir));
  if (mavlink) {
    plan.notes.push_back(
        fmt::format("fly: the autopilot is the simulator as a MAVLink vehicle ({} rules) through "
                    "wingman-mavlink over UDP on loopback",
                    o.firmware));
  }

  // The simulator: its defaults with these keys over them (--set, read by its config loader). Lockstep, paced at most
  // 5x real time: the logger is outside the loop. Unpaced, a truth-mode flight ran ~2600 frames/s and a loaded
  // machine's logger recorded 383 of 600 ground-truth frames; at 10x, 505-600 of 600 with six busy loops beside it; at
  // 5x, 600 of 600 in each of 10 such runs. Slower flights (rendering, the CNN) are not affected.
  // The processes the simulator waits for (status instance names): one detector, or detector<camera_id> per rig camera.
  std::string detector_names = "detector";
  if (!rig_cameras.empty()) {
    detector_names.clear();
    for (const auto& c : rig_cameras)
      detector_names += fmt::format("{}detector{}", detector_names.empty() ? "" : ", ", c.camera.camera_id);
  }
  const std::string wait_for =
      fmt::format("[{}, localizer, follower_ctrl{}]", detector_names, mavlink ? ", mavlink_bridge" : "");
  std::vector<std::string> sim_sets = {
      "--set",
      "scenario.file=" + plan.scenario_file,
      "--set",
      fmt::format("sync={{mode: lockstep, timeout_s: 10.0, max_speed: 5.0, wait_for: {}, startup_timeout_s: 60.0, "
                  "scripted_lockstep: {}, image_by_image: {}}}",
                  wait_for, bool_text(o.windows || !plan.rig_file.empty()), bool_text(!plan.rig_file.empty())),
      "--set",
      fmt::format("detections={{from_ground_truth: {}, box: {}, noise_px: 1.0, seed: {}}}", bool_text(!cnn),
                  o.truth_box, scenario_seed),
      "--set",
      fmt::format("render.enabled={}", bool_text(render)),
      "--set",
      "autopilot=" + o.autopilot,
      "--set",
      fmt::format("mavlink={{firmware: {}, streams: [odometry, attitude_quaternion, local_position_ned]}}",
                  o.firmware)};
  if (!o.own_pose_error.empty()) launcher::append_args(sim_sets, own_pose_sets(o.own_pose_error));
  if (!plan.rig_file.empty()) {
    launcher::append_args(sim_sets, {"--set", fmt::format("cameras.rig=\"{}\"", plan.rig_file)});
    plan.notes.push_back(fmt::format("fly: {} cameras from the rig {}, a detector each, fused by the localizer",
                                     rig_cameras.size(), plan.rig_file));
    if (o.camera_stagger_s > 0) {
      launcher::append_args(sim_sets, {"--set", fmt::format("cameras.stagger_s={}", o.camera_stagger_s)});
      plan.notes.push_back(fmt::format("fly: camera i exposes i x {} s after its frame's time", o.camera_stagger_s));
    }
  }

  // The flight's effective simulator configuration, as the loader merged it (a record; the process reads the --set).
  plan.sim_print_config.name = "wingman-sim --print-config";
  plan.sim_print_config.argv = {exe("wingman-sim")};
  launcher::append_args(plan.sim_print_config.argv, sim_sets);
  plan.sim_print_config.argv.push_back("--print-config");
  plan.sim_print_config.stdout_path = (fs::path(plan.out_dir) / "sim.yaml").string();

  plan.logger.name = "lcm-logger";
  plan.logger.argv = {"lcm-logger", "--lcm-url=" + url, "--force", "--quiet"};
  if (!o.record_images) launcher::append_args(plan.logger.argv, {"--channel=IMAGE_.*", "--invert-channels"});
  plan.logger.argv.push_back(plan.log_path);

  launcher::ProcessSpec detector =
      process("wingman-detector", {exe("wingman-detector"), "--lcm-url", url, "--set", "input.mode=replay"});
  if (cnn) {
    launcher::append_args(detector.argv, {"--set", fmt::format("model.cfg=\"{}\"", model_cfg), "--set",
                                          fmt::format("model.weights=\"{}\"", model_weights), "--set",
                                          fmt::format("detection.zoom_in={}", bool_text(o.zoom_in)), "--set",
                                          fmt::format("detection.flip_fusion={}", bool_text(o.flip_fusion)), "--set",
                                          fmt::format("detection.coarse_pass={}", bool_text(o.coarse_pass)), "--set",
                                          fmt::format("windows.enabled={}", bool_text(o.windows))});
  } else {
    launcher::append_args(detector.argv, {"--set", "model.weights=\"\""});
  }
  for (const auto& kv : o.detector_sets) launcher::append_args(detector.argv, {"--set", kv});
  // With a rig: one detector per camera, on that camera's channels (over the flight's sets), named detector<camera_id>
  // (its status channel).
  std::vector<launcher::ProcessSpec> detectors;
  if (rig_cameras.empty()) detectors.push_back(detector);
  for (const auto& c : rig_cameras) {
    launcher::ProcessSpec d = detector;
    d.name = fmt::format("wingman-detector-cam{}", c.camera.camera_id);
    launcher::append_args(d.argv, {"--name", fmt::format("detector{}", c.camera.camera_id), "--set",
                                   fmt::format("input.channel=\"{}\"", c.image_channel), "--set",
                                   fmt::format("output.channel=\"{}\"", c.detections_channel), "--set",
                                   fmt::format("windows.channel=\"{}\"", c.windows_channel)});
    detectors.push_back(d);
  }
  for (auto& d : detectors) launcher::append_args(d.argv, {"--log-level", "warn"});
  launcher::ProcessSpec localizer = process("wingman-localizer", {exe("wingman-localizer"), "--lcm-url", url});
  if (!localizer_config.empty()) launcher::append_args(localizer.argv, {"--config", localizer_config});
  if (o.windows) launcher::append_args(localizer.argv, {"--set", "windows.publish=true"});
  if (!plan.rig_file.empty())
    launcher::append_args(localizer.argv, {"--set", fmt::format("cameras.rig=\"{}\"", plan.rig_file)});
  for (const auto& kv : o.localizer_sets) launcher::append_args(localizer.argv, {"--set", kv});
  launcher::append_args(localizer.argv, {"--log-level", "warn"});
  launcher::ProcessSpec follower = process("wingman-follower-ctrl", {exe("wingman-follower-ctrl"), "--lcm-url", url});
  if (!follower_config.empty()) launcher::append_args(follower.argv, {"--config", follower_config});
  for (const auto& kv : o.follower_sets) launcher::append_args(follower.argv, {"--set", kv});
  launcher::append_args(follower.argv, {"--log-level", "warn"});
  plan.pipeline = detectors;
  plan.pipeline.push_back(localizer);
  plan.pipeline.push_back(follower);
  if (mavlink) {
    const std::string bridge_config = (fs::path(o.config_dir) / "mavlink_bridge.sim.yaml").string();
    if (!readable_file(bridge_config))
      throw std::invalid_argument(fmt::format("--config-dir {}: cannot read {}", o.config_dir, bridge_config));
    plan.pipeline.push_back(process("wingman-mavlink", {exe("wingman-mavlink"), "--lcm-url", url, "--config",
                                                        absolute(bridge_config), "--log-level", "info"}));
  }

  plan.sim.name = "wingman-sim";
  plan.sim.argv = {exe("wingman-sim"), "--lcm-url", url};
  launcher::append_args(plan.sim.argv, sim_sets);
  if (o.duration_s > 0.0) launcher::append_args(plan.sim.argv, {"--duration", fmt::format("{}", o.duration_s)});
  if (!render_config.empty()) launcher::append_args(plan.sim.argv, {"--render-config", render_config});

  // The formation error is measured against the follower's own target: eval reads the follower's configuration
  // (formation.offset_m) and, for the 1-D follow, the scenario's start (the leader moved back to the follower's line).
  plan.eval.log = plan.log_path;
  plan.eval.report_path = (fs::path(plan.out_dir) / "report.html").string();
  plan.eval.json_path = (fs::path(plan.out_dir) / "eval.json").string();
  plan.eval.csv_path = (fs::path(plan.out_dir) / "targets.csv").string();
  plan.eval.title = "Wingman flight: " + plan.name;
  plan.eval_target.scenario = plan.scenario_file;
  if (!follower_config.empty()) plan.eval_target.follower.files = {follower_config};
  plan.eval_target.follower.sets = o.follower_sets;
  // What the formation error is measured against, known before the flight (a bad follower key fails here).
  plan.eval.formation_offset_in_world =
      formation_offset_for(plan.eval_target, plan.eval.follower_id, plan.eval.leader_id);
  plan.eval.has_formation = true;
  return plan;
}

namespace {
/// `name_or_file` when it is a file, else `config_dir`/`folder`/NAME.yaml (not checked to exist).
std::string file_or_named(const std::string& name_or_file, const std::string& config_dir, const char* folder) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_file, ec)) return name_or_file;
  return (fs::path(config_dir) / folder / (name_or_file + ".yaml")).string();
}
}  // namespace

std::string rig_file(const std::string& rig, const std::string& config_dir) {
  return file_or_named(rig, config_dir, "rigs");
}

std::string scenario_file(const std::string& scenario, const std::string& config_dir) {
  return file_or_named(scenario, config_dir, "scenarios");
}

int fly(const FlightPlan& plan, std::ostream& out, std::ostream& err) {
  for (const auto& line : plan.notes) out << line << '\n';
  out << std::flush;
  fs::create_directories(plan.out_dir);
  std::error_code ec;
  fs::remove(plan.log_path, ec);

  launcher::StopSignals signals;
  launcher::ProcessGroup group;
  if (const int rc = group.run(plan.sim_print_config); rc != 0) {
    err << "fly: " << plan.sim_print_config.command_line() << " failed (exit " << rc << ")" << std::endl;
    return rc;
  }
  const size_t logger = group.start(plan.logger);
  std::vector<size_t> pipeline;
  for (const auto& spec : plan.pipeline) pipeline.push_back(group.start(spec));
  const auto t0 = std::chrono::steady_clock::now();
  const size_t sim = group.start(plan.sim);

  // The flight: until the simulator ends. A pipeline process or the logger that ends first (or a stop signal) ends
  // the flight.
  std::vector<size_t> watched = pipeline;
  watched.push_back(logger);
  watched.push_back(sim);
  const std::optional<size_t> ended = group.wait_any(watched, [&] { return signals.requested(); });
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int rc = 0;
  if (!ended) {
    err << "fly: stopped by signal " << signals.signal() << ": stopping the flight" << std::endl;
    rc = 130;
  } else if (*ended != sim) {
    err << "fly: " << group.spec(*ended).label() << " ended (exit " << *group.poll(*ended)
        << ") while the flight ran: stopping the flight; its command was: " << group.spec(*ended).command_line()
        << std::endl;
    rc = 1;
  } else if (const int sim_rc = *group.poll(sim); sim_rc != 0) {
    err << "fly: wingman-sim failed (exit " << sim_rc << ")" << std::endl;
    rc = sim_rc;
  }
  // Stop the pipeline first (each process publishes a last STOPPING status), then the logger.
  std::vector<size_t> first = {sim};
  first.insert(first.end(), pipeline.begin(), pipeline.end());
  group.stop(first, kPipelineGraceS);
  std::this_thread::sleep_for(std::chrono::duration<double>(kLoggerTailS));
  group.stop({logger}, kPipelineGraceS);
  if (rc != 0) return rc;

  out << "\nfly: " << plan.name << " flown in " << static_cast<int>(wall_s)
      << " s of wall-clock time; errors against ground truth:" << std::endl;
  EvalOptions eval = plan.eval;
  eval.progress = &err;
  const EvalResult result = evaluate_log(eval);
  write_html_report(result, eval, eval.report_path);
  out << result.report() << std::flush;
  err << "report written to " << eval.report_path << std::endl;
  out << "fly: log " << plan.log_path << ", report " << eval.report_path << std::endl;
  return 0;
}

}  // namespace wingman::tools
