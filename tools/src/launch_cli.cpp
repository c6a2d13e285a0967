// SPDX-License-Identifier: MIT
// The launching verbs' command lines: `wingman fly` (tools/fly.sh's flags, bound to FlyOptions), `wingman demo-camera`
// (tools/demo_camera.sh's pipeline run) and `wingman load` (tools/load_test.sh's and tools/soak.sh's).
#include "wingman/tools/launch_cli.hpp"

#include "run_verb.hpp"
#include "verb_layers.hpp"
#include "wingman/tools/demo_camera.hpp"
#include "wingman/tools/load.hpp"
#ifdef WINGMAN_WITH_SIM
#include "wingman/tools/experiment.hpp"
#include "wingman/tools/fly.hpp"
#endif

#include <wingman/common/config.hpp>

#include <initializer_list>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>

namespace wingman::tools {

struct LaunchVerbs::State {
  CLI::App* demo = nullptr;
  DemoCameraOptions demo_options;  // what the flags say (only the flags given count: VerbLayers)
  std::unique_ptr<VerbLayers> demo_layers;
  CLI::App* load = nullptr;
  LoadOptions load_options;
  std::unique_ptr<VerbLayers> load_layers;
#ifdef WINGMAN_WITH_SIM
  CLI::App* fly = nullptr;
  FlyOptions options;
  bool render = false, no_render = false;
  std::unique_ptr<VerbLayers> fly_layers;
  CLI::App* experiment = nullptr;
  ExperimentOptions experiment_options;
  bool list_experiments = false;
  std::unique_ptr<VerbLayers> experiment_layers;
#endif
};

LaunchVerbs::LaunchVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  DemoCameraOptions& d = s_->demo_options;
  s_->demo = app.add_subcommand(
      "demo-camera",
      "Play a video through wingman-camera-driver into the running pipeline (detector, localizer, follower: their "
      "built-in defaults) on the LCM bus, record the bus and show what arrived. Run it in a private network namespace "
      "(tools/demo_camera.sh does)");
  s_->demo->add_option("video", d.video, "The clip to play once at its own rate (or demo.video)");
  s_->demo->add_option("--out", d.out, "Output folder: demo.lcmlog, last_frame.png");
  s_->demo->add_option("--start-timeout", d.start_timeout_s,
                       "Seconds to wait for every pipeline process's first heartbeat");
  s_->demo->add_option("--settle-timeout", d.settle_timeout_s,
                       "Seconds to wait after the clip for the detector to account for every frame");
  s_->demo->add_option("--bin-dir", d.bin_dir, "The executables (empty: the folder of this wingman)");
  s_->demo->add_option("--lcm-url", d.lcm_url, "The LCM bus (empty: $WINGMAN_LCM_URL, set by tools/netns_run.sh)");
  s_->demo_layers = std::make_unique<VerbLayers>(s_->demo);
  for (const auto& [flag, key, quote] : std::initializer_list<std::tuple<const char*, const char*, bool>>{
           {"video", "demo.video", true},
           {"--out", "demo.out", true},
           {"--start-timeout", "demo.start_timeout_s", false},
           {"--settle-timeout", "demo.settle_timeout_s", false},
           {"--bin-dir", "run.bin_dir", true},
           {"--lcm-url", "run.lcm_url", true},
       }) {
    s_->demo_layers->key(flag, key, quote);
  }
  s_->demo_layers->check_every_flag({});
  LoadOptions& l = s_->load_options;
  auto* ld = s_->load = app.add_subcommand(
      "load",
      "The four-camera load test (the thesis's 360-degree case) through the real processes on the LCM bus: camera N "
      "plays a 1280x720 30-fps clip in a loop (MJPEG on the bus by default: load.encoding), detector N (the shipped "
      "model) works on it, one localizer fuses the cameras (load.rig), one follower follows its targets; lcm-logger "
      "records all but the images; tools/load_summary.py "
      "computes the figures and checks. Run it in a private network namespace (tools/load_test.sh and tools/soak.sh "
      "do)");
  ld->add_option("--mode", l.mode,
                 "realtime: cameras paced at 30 fps, detectors keep the newest frame when busy; checks that every "
                 "frame received is processed or counted as dropped, that frames lost on the bus stay under 20 % and "
                 "match kernel receive-buffer drops, the end-to-end p99 and the p50 trend. replay: the cameras write "
                 "their frames into one LCM log, the detectors read it file to file; checks that every image got its "
                 "detections (the input log is deleted after a passing run)")
      ->check(CLI::IsMember({"realtime", "replay"}));
  ld->add_option("--duration", l.duration_s, "realtime: seconds the cameras play (0: 30, or 600 with --soak)");
  ld->add_option("--out", l.out, "Output folder (empty: build/load/MODE, build/load/soak with --soak)");
  ld->add_option("--cameras", l.cameras, "Camera chains, 1..4")->check(CLI::Range(1, 4));
  ld->add_flag("--soak", l.soak,
               "Realtime, and every process's RSS sampled: fails when one grows by more than --max-rss-growth-pct "
               "after --warmup (peak of the first third after it against the last third); prints the latency trend");
  ld->add_option("--warmup", l.warmup_s,
                 "Soak: seconds after the cameras start before RSS is the reference (0: 30 up to 180-s runs, else 60): "
                 "model loading, kernel builds and buffers growing to a 2.7 MB image happen then");
  ld->add_option("--sample-period", l.sample_period_s, "Seconds between RSS/CPU samples from /proc");
  ld->add_option("--replay-frames", l.replay_frames, "Replay: frames per camera (2.7 MB each in the log)");
  ld->add_option("--max-p99-s", l.max_p99_s, "Realtime: bound on the end-to-end p99, seconds");
  ld->add_option("--max-rss-growth-pct", l.max_rss_growth_pct, "Soak: bound on RSS growth after the warm-up, percent");
  ld->add_flag("--report-only", l.report_only,
               "The speed and memory bounds are reported, not checked (the frame accounting and the statuses stay "
               "checks): CI's load tests, on a shared machine");
  ld->add_option("--summary-script", l.summary_script, "The figures and checks (Python, the generated LCM types)");
  ld->add_option("--bin-dir", l.bin_dir, "The executables (empty: the folder of this wingman)");
  ld->add_option("--lcm-url", l.lcm_url, "The LCM bus (empty: $WINGMAN_LCM_URL, set by tools/netns_run.sh)");
  s_->load_layers = std::make_unique<VerbLayers>(ld);
  for (const auto& [flag, key, quote] : std::initializer_list<std::tuple<const char*, const char*, bool>>{
           {"--mode", "load.mode", true},
           {"--duration", "load.duration_s", false},
           {"--out", "load.out", true},
           {"--cameras", "load.cameras", false},
           {"--soak", "load.soak", false},
           {"--warmup", "load.warmup_s", false},
           {"--sample-period", "load.sample_period_s", false},
           {"--replay-frames", "load.replay_frames", false},
           {"--max-p99-s", "checks.max_p99_s", false},
           {"--max-rss-growth-pct", "checks.max_rss_growth_pct", false},
           {"--report-only", "checks.report_only", false},
           {"--summary-script", "run.summary_script", true},
           {"--bin-dir", "run.bin_dir", true},
           {"--lcm-url", "run.lcm_url", true},
       }) {
    s_->load_layers->key(flag, key, quote);
  }
  s_->load_layers->check_every_flag({});
#ifdef WINGMAN_WITH_SIM
  FlyOptions& o = s_->options;
  auto* f = s_->fly = app.add_subcommand(
      "fly",
      "Fly a simulated scenario through the real pipeline: wingman-sim, wingman-detector, wingman-localizer and "
      "wingman-follower-ctrl as separate processes on the LCM bus, in lockstep (deterministic); record the bus, print "
      "the localization and formation errors and write an HTML report. Run it in a private network namespace "
      "(tools/fly.sh does)");
  f->add_option("--scenario", o.scenario, "config/scenarios/NAME.yaml (under --config-dir) or a scenario file");
  f->add_option("--out", o.out,
                "Output folder: flight.lcmlog, sim.yaml, eval.json, targets.csv, report.html "
                "(empty: build/flights/NAME)");
  f->add_option("--duration", o.duration_s, "Stop after this many simulated seconds (0: the scenario's own length)");
  f->add_option("--detections", o.detections,
                "cnn: the detector finds the leader in the rendered images with its model; truth: the simulator "
                "publishes boxes projected from ground truth (flagged as such down to the setpoints) and the detector "
                "runs without a model")
      ->check(CLI::IsMember({"cnn", "truth"}));
  f->add_flag("--render", s_->render, "Render the camera images (1280x720); always with cnn");
  f->add_flag("--no-render", s_->no_render, "No images (ground-truth detections need none); the default with truth");
  f->add_flag("--record-images", o.record_images, "Also record the camera images in the log (2.7 MB a frame)");
  f->add_option("--truth-box", o.truth_box,
                "Ground-truth detections: the bounding sphere's exact box (the localizer's model) or the drone's "
                "silhouette box")
      ->check(CLI::IsMember({"sphere", "silhouette"}));
  f->add_flag("--zoom-in", o.zoom_in, "The detector re-detects each box in a full-resolution crop");
  f->add_flag("--flip-fusion", o.flip_fusion, "The detector also detects in the mirrored frame and fuses both passes");
  f->add_flag("--coarse-pass", o.coarse_pass, "The detector also detects at half the network input (close drones)");
  f->add_flag("--windows", o.windows,
              "Tracker-driven windows: the localizer publishes where its tracks will be in the next frame and the "
              "detector searches there at full resolution (windows.* of both; docs/detector.md)");
  f->add_option("--rig", o.rig,
                "Several cameras: config/rigs/NAME.yaml (under --config-dir) or a rig file; the simulator renders "
                "each, a detector runs per camera and the localizer fuses them (empty: the one forward camera)");
  f->add_option("--camera-stagger", o.camera_stagger_s,
                "With --rig: camera i exposes i x this many seconds after its frame's time (cameras not triggered "
                "together; the simulator's cameras.stagger_s); 0: together");
  f->add_option("--localizer-config", o.localizer_config,
                "The localizer's config (empty: config/flights/NAME.localizer.yaml if any, else its defaults)");
  f->add_option("--follower-config", o.follower_config,
                "The follower's config (empty: config/flights/NAME.follower_ctrl.yaml if any, else its defaults); its "
                "formation.offset_m is also what the formation error is measured against");
  f->add_option("--render-config", o.render_config,
                "The simulator's render.* keys (lighting, scene) from this file (wingman-sim --render-config)");
  f->add_option("--autopilot", o.autopilot,
                "lcm: the simulator takes SETPOINT and publishes OWN_POSE; mavlink: the simulator is a MAVLink "
                "vehicle on UDP loopback and wingman-mavlink bridges it (config/mavlink_bridge.sim.yaml)")
      ->check(CLI::IsMember({"lcm", "mavlink"}));
  f->add_option("--firmware", o.firmware, "With --autopilot mavlink: the simulated autopilot's rules")
      ->check(CLI::IsMember({"px4", "ardupilot"}));
  f->add_option("--own-pose-error", o.own_pose_error,
                "M,RAD[,TAU]: the follower's reported pose drifts (Gauss-Markov, correlation time TAU s, default 2) "
                "by M metres per position axis and RAD radians per rotation (standard deviations); empty: exact")
      ->type_name("M,RAD[,TAU]");
  f->add_option("--model-cfg", o.model_cfg,
                "The detector's network (empty: beside --model-weights, or the built-in shipped model)")
      ->envname("WINGMAN_MODEL_CFG");
  f->add_option("--model-weights", o.model_weights, "The detector's weights (empty: the built-in shipped model)")
      ->envname("WINGMAN_MODEL_WEIGHTS");
  f->add_option("--config-dir", o.config_dir, "The checkout's config folder (scenarios, flights, MAVLink bridge)");
  f->add_option("--bin-dir", o.bin_dir, "The executables (empty: the folder of this wingman)");
  f->add_option("--lcm-url", o.lcm_url, "The LCM bus (empty: $WINGMAN_LCM_URL, set by tools/netns_run.sh)");
  f->add_option("--localizer-set", o.localizer_sets, "KEY=VALUE over the localizer's configuration (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  f->add_option("--follower-set", o.follower_sets,
                "KEY=VALUE over the follower's configuration (repeatable; the formation error follows it)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  f->add_option("--detector-set", o.detector_sets, "KEY=VALUE over the detector's configuration (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  // A flight as data: the one loader's layers (defaults, --config files, --set), and the flags given over them.
  s_->fly_layers = std::make_unique<VerbLayers>(f);
  for (const auto& [flag, key, quote] : std::initializer_list<std::tuple<const char*, const char*, bool>>{
           {"--scenario", "flight.scenario", true},
           {"--out", "flight.out", true},
           {"--duration", "flight.duration_s", false},
           {"--detections", "flight.detections", true},
           {"--record-images", "flight.record_images", false},
           {"--truth-box", "flight.truth_box", true},
           {"--zoom-in", "detector.zoom_in", false},
           {"--flip-fusion", "detector.flip_fusion", false},
           {"--coarse-pass", "detector.coarse_pass", false},
           {"--windows", "windows.enabled", false},
           {"--rig", "cameras.rig", true},
           {"--camera-stagger", "cameras.stagger_s", false},
           {"--localizer-config", "processes.localizer_config", true},
           {"--follower-config", "processes.follower_config", true},
           {"--render-config", "processes.render_config", true},
           {"--autopilot", "autopilot.kind", true},
           {"--firmware", "autopilot.firmware", true},
           {"--own-pose-error", "flight.own_pose_error", true},
           {"--model-cfg", "detector.model_cfg", true},
           {"--model-weights", "detector.model_weights", true},
           {"--localizer-set", "processes.localizer_set", true},
           {"--follower-set", "processes.follower_set", true},
           {"--detector-set", "processes.detector_set", true},
           {"--config-dir", "run.config_dir", true},
           {"--bin-dir", "run.bin_dir", true},
           {"--lcm-url", "run.lcm_url", true},
       }) {
    s_->fly_layers->key(flag, key, quote);
  }
  s_->fly_layers->check_every_flag({"--render", "--no-render"});  // flight.render, from both

  ExperimentOptions& x = s_->experiment_options;
  auto* e = s_->experiment = app.add_subcommand(
      "experiment",
      "Run experiments as their files say (config/experiments/NAME.yaml: the flights, their scenarios and settings, "
      "the table over them): each flight through `wingman fly`, then tools/experiment_summary.py's table "
      "(results.md, results.json) in OUT/NAME. Run it in a private network namespace (tools/experiment.sh does)");
  e->add_option("names", x.names, "Experiments in order: NAME (config/experiments/NAME.yaml) or an experiment file")
      ->type_name("NAME|FILE");
  e->add_flag("--list", s_->list_experiments, "List the experiments (config/experiments) with their titles and exit");
  e->add_flag("--quick", x.quick, "Short flights and sparse sweeps (each file's quick: parts): a check, not results");
  e->add_option("--out", x.out, "Output root (empty: build/experiments, or build/experiments-truth with truth)");
  e->add_option("--detections", x.detections,
                "cnn: the shipped model on rendered images; truth: boxes from the simulator's ground truth (no "
                "rendering), for the experiments whose files allow it")
      ->check(CLI::IsMember({"cnn", "truth"}));
  e->add_option("--duration", x.duration_s,
                "Fly only the first S seconds of every flight, sweeps included (0: their own length)");
  e->add_option("--meshes", x.meshes,
                "The four shared airframes (empty: $WINGMAN_SHARED_MESHES, else ../shared/meshes; absent: the flights "
                "that need them are skipped, their stand-ins fly)");
  e->add_flag("--dry-run", x.dry_run,
              "Write the scenarios and plan every flight (all of wingman fly's checks), print the plans, fly nothing");
  e->add_option("--summary-script", x.summary_script, "The tables (Python, run with python3)");
  e->add_option("--config-dir", x.config_dir, "The checkout's config folder (experiments, scenarios, flights)");
  e->add_option("--bin-dir", x.bin_dir, "The executables (empty: the folder of this wingman)");
  e->add_option("--lcm-url", x.lcm_url, "The LCM bus (empty: $WINGMAN_LCM_URL, set by tools/netns_run.sh)");
  s_->experiment_layers = std::make_unique<VerbLayers>(e);
  for (const auto& [flag, key, quote] : std::initializer_list<std::tuple<const char*, const char*, bool>>{
           {"names", "experiment.names", true},
           {"--quick", "experiment.quick", false},
           {"--out", "experiment.out", true},
           {"--detections", "experiment.detections", true},
           {"--duration", "experiment.duration_s", false},
           {"--meshes", "experiment.meshes", true},
           {"--dry-run", "experiment.dry_run", false},
           {"--summary-script", "run.summary_script", true},
           {"--config-dir", "run.config_dir", true},
           {"--bin-dir", "run.bin_dir", true},
           {"--lcm-url", "run.lcm_url", true},
       }) {
    s_->experiment_layers->key(flag, key, quote);
  }
  s_->experiment_layers->check_every_flag({"--list"});
#endif
}

LaunchVerbs::~LaunchVerbs() = default;

int LaunchVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  if (*s_->demo) {
    return run_verb("wingman demo-camera", err, [&] {
      bool printed = false;
      const auto o = s_->demo_layers->load<DemoCameraOptions>(out, &printed);
      return printed ? 0 : run_demo_camera(o, out, err);
    });
  }
  if (*s_->load) {
    return run_verb("wingman load", err, [&] {
      bool printed = false;
      const auto o = s_->load_layers->load<LoadOptions>(out, &printed);
      return printed ? 0 : run_load(o, out, err);
    });
  }
#ifdef WINGMAN_WITH_SIM
  if (*s_->experiment) {
    return run_verb("wingman experiment", err, [&] {
      if (s_->list_experiments) {
        list_experiments(s_->experiment_options.config_dir, out);
        return 0;
      }
      bool printed = false;
      const auto o = s_->experiment_layers->load<ExperimentOptions>(out, &printed);
      return printed ? 0 : run_experiments(o, out, err);
    });
  }
  if (!*s_->fly) return -1;
  return run_verb("wingman fly", err, [&] {
    if (s_->render && s_->no_render) throw std::invalid_argument("--render and --no-render: give one");
    // The flags given become the last --set layer (they win); every value goes through the one loader.
    std::vector<std::string> render;
    if (s_->render) render.push_back("flight.render=on");
    if (s_->no_render) render.push_back("flight.render=off");
    bool printed = false;
    const FlyOptions o = s_->fly_layers->load<FlyOptions>(out, &printed, render);
    if (printed) return 0;
    return fly(plan_flight(o), out, err);
  });
#else
  return -1;
#endif
}

}  // namespace wingman::tools
