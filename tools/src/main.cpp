// SPDX-License-Identifier: MIT
// `wingman`: the tools CLI. Verbs: replay (deterministic log player), spy, loginfo, make-video, localize, predict,
// bench detector, eval (flight errors against ground truth), report (its HTML page), dataset synth, scenario random
// (out-of-sample flights), train / val / import-halmstad (training; `train` runs in wingman-train).
#include "wingman/tools/bench.hpp"
#include "wingman/tools/eval.hpp"
#include "wingman/tools/eval_target.hpp"
#include "wingman/tools/forwarded_verbs.hpp"
#include "wingman/tools/launch_cli.hpp"
#include "wingman/tools/localize.hpp"
#include "wingman/tools/log_info.hpp"
#include "wingman/tools/make_video.hpp"
#include "wingman/tools/model_cli.hpp"
#include "wingman/tools/predict.hpp"
#include "wingman/tools/recipe_cli.hpp"
#include "wingman/tools/replay.hpp"
#include "wingman/tools/report.hpp"
#include "wingman/tools/spy.hpp"
#include "wingman/tools/train_cli.hpp"
#ifdef WINGMAN_WITH_SIM
#include "wingman/tools/dataset_synth.hpp"
#include "wingman/tools/scenario_random.hpp"
#endif

#include "tidy_defaults.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <wingman/common/version.hpp>

#include <iostream>
#include <string>
#include <tuple>

int main(int argc, char** argv) {
  using namespace wingman::tools;
  CLI::App app{"Wingman tools: replay logs through the pipeline, monitor and inspect it", "wingman"};
  app.require_subcommand(1);
  // Every verb's help shows each option's default from the variable it is bound to (subcommands inherit this).
  app.option_defaults()->always_capture_default();
  app.set_version_flag("--version", std::string("wingman ") + wingman::common::version(),
                       "Print the version (and the commit built from) and exit");

  ReplayOptions replay;
  auto* r = app.add_subcommand(
      "replay", "Play an LCM log into the pipeline; with --wait-for, in lockstep with the named processes");
  r->add_option("log", replay.input_log, "Input LCM log file")->required();
  r->add_option("--lcm-url", replay.lcm_url, "LCM URL to publish on and listen to (empty: LCM_DEFAULT_URL)");
  r->add_option("--wait-for", replay.stages,
                "Process instance names (as in their status) to run in lockstep with; each must run with --lockstep")
      ->delimiter(',');
  r->add_option("--channels", replay.channels, "Regular expression of channels to play (empty: all but STATUS_*)");
  r->add_option("--exclude", replay.exclude,
                "Regular expression of channels not to play (e.g. the stages' own outputs)");
  r->add_option("--record", replay.record_log, "Write every message seen on the bus (but status) to this LCM log");
  r->add_option("--speed", replay.speed, "Without --wait-for: playback speed (1 = real time, 0 = as fast as possible)");
  r->add_option("--start-timeout", replay.start_timeout_s, "Seconds to wait for every --wait-for process to report");
  r->add_option("--step-timeout", replay.step_timeout_s,
                "Seconds to wait for the pipeline to settle after each message");
  r->add_option("--max-events", replay.max_events, "Play at most this many events (0 = all)");
  bool replay_quiet = false;
  r->add_flag("--quiet", replay_quiet, "No progress on stderr");
  r->add_flag("--skip-corrupt", replay.skip_corrupt,
              "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");

  SpyOptions spy;
  auto* s = app.add_subcommand("spy", "Start lcm-spy with the Wingman message types");
  s->add_option("--lcm-url", spy.lcm_url, "LCM URL to listen on (empty: LCM_DEFAULT_URL)");
  s->add_option("--java", spy.java, "Java runtime");
  s->add_option("--types-jar", spy.types_jar, "Jar with the wingman message classes (empty: the built one)");
  s->add_flag("--dry-run", spy.dry_run, "Print the java command instead of running it");

  MakeVideoOptions video;
  auto* mv =
      app.add_subcommand("make-video", "Write a synthetic test clip (MJPG .avi) for the camera driver's file source");
  mv->add_option("output", video.output, "Output .avi file")->required();
  mv->add_option("--frames", video.frames, "Number of frames");
  mv->add_option("--width", video.width, "Width, pixels");
  mv->add_option("--height", video.height, "Height, pixels");
  mv->add_option("--fps", video.fps, "Frames per second");

  std::string info_log, info_snapshot;
  bool info_skip_corrupt = false;
  auto* li =
      app.add_subcommand("loginfo", "Summarize an LCM log: channels, types, counts, time spans, process statuses");
  li->add_option("log", info_log, "LCM log file")->required();
  li->add_option("--snapshot", info_snapshot, "Save the last image_t as this PNG file");
  li->add_flag(
      "--skip-corrupt", info_skip_corrupt,
      "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");

  LocalizeToolOptions localize;
  auto* lo = app.add_subcommand(
      "localize",
      "Localize one box: calibration file + target radius + box -> direction, range, camera-frame position");
  lo->add_option("calibration", localize.calibration, "Calibration file: ROS camera_info, OpenCV FileStorage or Kalibr")
      ->required();
  lo->add_option("--box", localize.box, "Box cx,cy,w,h in pixels (origin at the top-left pixel's corner)")
      ->required()
      ->expected(4)
      ->delimiter(',');
  lo->add_option("--radius", localize.localizer.radius_m, "Target bounding-sphere radius, metres (the default: F450)");
  lo->add_option("--method", localize.localizer.range_method, "exact, thesis (eq. 32) or thesis_eq33");
  lo->add_option("--min-range", localize.localizer.min_range_m, "Reject ranges below this, metres");
  lo->add_option("--max-range", localize.localizer.max_range_m, "Reject ranges above this, metres");
  lo->add_option("--edge-noise", localize.localizer.edge_noise_px, "Box edge noise, pixels");
  lo->add_option("--edge-noise-rel", localize.localizer.edge_noise_rel,
                 "Plus this fraction of the box width/height per edge, in quadrature");
  lo->add_option("--centre-noise", localize.localizer.centre_noise_px, "Box centre noise, pixels");
  lo->add_option("--border-margin", localize.localizer.border_margin_px,
                 "An edge this close to the image edge is cut, pixels");
  lo->add_option("--kalibr-camera", localize.kalibr_camera, "Camera entry of a Kalibr camchain");
  lo->add_option("--image-size", localize.image_size, "WxH of the images the box comes from; a mismatch is an error");
  lo->add_flag("--scale-calibration", localize.scale_calibration,
               "With --image-size: scale the calibration to that size (a uniform resize) instead of failing");
  lo->add_flag("--json", localize.json, "Print one JSON object");

  PredictOptions predict;
  auto* pr = app.add_subcommand(
      "predict", "Run the detector on image files or folders; write YOLO-format labels (and drawn images)");
  pr->add_option("inputs", predict.inputs, "Image files and/or folders of images")->required();
  pr->add_option("--cfg", predict.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
  pr->add_option("--weights", predict.weights,
                 "Darknet .weights, or builtin:wingman-small (the shipped model, models/wingman-small.md)");
  pr->add_option("--backend", predict.backend, "Inference backend: auto, opencl or cpu");
  pr->add_option("--input-size", predict.input_size,
                 "Network input: auto (the cfg's longer side, the other fitted to each image's aspect), cfg or WxH");
  pr->add_option("--out", predict.out_dir, "Output folder for <stem>.txt");
  pr->add_flag("--draw", predict.draw, "Also write <stem>.pred.jpg with the boxes drawn");
  pr->add_option("--p-thresh", predict.detection.p_thresh, "Confidence threshold");
  pr->add_option("--o-thresh", predict.detection.o_thresh, "Non-max suppression IoU threshold");
  pr->add_flag("--subsquare", predict.detection.subsquare, "Detect in the centred h x h square of a wide image");
  pr->add_flag("--zoom-in", predict.detection.zoom_in, "Re-detect in full-resolution crops around detections");
  pr->add_flag("--drone-first", predict.detection.drone_first,
               "Multi-class models: a box whose drone score reaches the threshold is a drone even if another class "
               "scores higher");
  pr->add_flag("--flip-fusion", predict.detection.flip_fusion,
               "Also detect in the mirrored image and fuse both passes' boxes (twice the work)");
  pr->add_option("--fusion-iou", predict.detection.fusion_iou,
                 "--flip-fusion, --coarse-pass: fuse the passes' boxes overlapping above this IoU");
  pr->add_flag("--coarse-pass", predict.detection.coarse_pass,
               "Also detect at --coarse-scale of the network input and fuse its large boxes (close drones)");
  pr->add_option("--coarse-scale", predict.detection.coarse_scale,
                 "--coarse-pass: network input sides times this, multiples of 32");
  pr->add_option("--coarse-min-size", predict.detection.coarse_min_size,
                 "--coarse-pass: drop its boxes below this sqrt(w h), image pixels");
  pr->add_option("--policy", predict.detection.policy, "all or most_confident");
  pr->add_option("--max-detections", predict.detection.max_detections, "At most this many boxes per image");

  // `eval` and `report` read a flight's log the same way; both take the matching options.
  EvalOptions eval, report;
  std::vector<double> eval_offset, report_offset;
  FlightTargetSources eval_target, report_target;
  bool eval_json_stdout = false, eval_quiet = false, report_quiet = false;
  const auto add_eval_options = [](CLI::App* c, EvalOptions& o, std::vector<double>& offset,
                                   FlightTargetSources& target, bool& quiet) {
    c->add_option("log", o.log, "LCM log with GROUND_TRUTH and TARGETS (and DETECTIONS_CAM0, IMAGE_CAM0)")->required();
    c->add_option("--formation-offset", offset, "Desired follower minus leader position x,y,z (ENU), metres")
        ->expected(3)
        ->delimiter(',');
    c->add_option("--follower-config", target.follower.files,
                  "The follower's configuration (wingman-follower-ctrl --config; repeatable, a later file wins): the "
                  "formation error is measured against its target (mode formation: formation.offset_m; mode pid_1d: "
                  "the leader moved to the follower's starting line, from --scenario)")
        ->allow_extra_args(false)
        ->type_name("FILE");
    c->add_option("--follower-set", target.follower.sets,
                  "KEY=VALUE over --follower-config, as wingman-follower-ctrl --set (repeatable)")
        ->allow_extra_args(false)
        ->type_name("KEY=VALUE");
    c->add_option("--scenario", target.scenario,
                  "The flight's scenario file (read with wingman-sim's loader): the vehicles' start for a pid_1d "
                  "follower (ids --follower-id and --leader-id); with it and no --follower-config, the follower's "
                  "built-in defaults are its configuration");
    c->add_option("--formation-height", o.formation_height_m,
                  "The follower's constant height, metres (negative: the formation offset's z)");
    c->add_option("--settle", o.settle_s, "Skip this many seconds before measuring formation error");
    c->add_option("--leader-id", o.leader_id, "vehicle_id of the leader in ground truth");
    c->add_option("--follower-id", o.follower_id, "vehicle_id of the camera vehicle");
    c->add_option("--match-radius", o.match_radius_m, "Farther targets are false targets, metres");
    c->add_option("--range-bins", o.range_bins_m,
                  "Upper edges of the range bins, metres, increasing; the last bin is open (the default: 0-5, ..., "
                  "30+)")
        ->delimiter(',');
    c->add_option("--truth-channel", o.truth_channel, "ground_truth_t channel");
    c->add_option("--targets-channel", o.targets_channel, "targets_t channel");
    c->add_option("--detections-channel", o.detections_channel, "detections_t channel");
    c->add_option("--image-channel", o.image_channel, "image_t channel");
    c->add_option("--title", o.title, "Report title");
    c->add_option("--frames", o.report_frames, "Camera frames shown in the report");
    c->add_flag("--quiet", quiet, "No progress on stderr");
  };
  auto* ev = app.add_subcommand(
      "eval", "Localization, tracking, latency and box errors of a simulated flight's log against its ground truth");
  add_eval_options(ev, eval, eval_offset, eval_target, eval_quiet);
  ev->add_option("--json", eval.json_path,
                 "Also write the result as JSON to this file; - prints it instead of the table");
  ev->add_flag("--json-stdout", eval_json_stdout, "Print JSON instead of the table (the same as --json -)");
  ev->add_option("--csv", eval.csv_path, "Write the per-target time series (t, track, range, estimate, truth, error)");
  ev->add_option("--report", eval.report_path, "Write a self-contained HTML report to this file");
  auto* rp = app.add_subcommand(
      "report", "One self-contained HTML page about a simulated flight: charts and camera frames (opens offline)");
  add_eval_options(rp, report, report_offset, report_target, report_quiet);
  rp->add_option("-o,--out,--output", report.report_path, "HTML file to write")->required();
  rp->add_option("--json", report.json_path, "Also write the result as JSON to this file");
  rp->add_option("--csv", report.csv_path, "Also write the per-target time series as CSV to this file");

  BenchDetectorOptions bench_detector;
  auto* be = app.add_subcommand("bench", "Benchmarks (numbers, not tests)");
  be->require_subcommand(1);
  auto* bd = be->add_subcommand("detector",
                                "A network (the thesis network unless --cfg) per frame: OpenCL vs CpuBackend vs "
                                "bare OpenCV DNN, and the whole pipeline");
  bd->add_option("--sizes", bench_detector.sizes,
                 "Network input sizes: N (N x N) or WxH, multiples of 32, or cfg (the network's own)")
      ->delimiter(',');
  bd->add_option("--threads", bench_detector.threads, "OpenCV thread counts; OpenCL: POCL_MAX_PTHREAD_COUNT")
      ->delimiter(',');
  bd->add_option("--repetitions", bench_detector.repetitions, "Timed runs per row");
  bd->add_option("--warmup", bench_detector.warmup, "Untimed runs before each row");
  bd->add_option("--cfg", bench_detector.cfg,
                 "Network: a .cfg, builtin:tiny-yolo-thesis or builtin:wingman-small (the shipped model)");
  bd->add_option("--weights", bench_detector.weights,
                 "Darknet .weights or builtin:wingman-small (empty: random weights, --seed)");
  bd->add_option("--seed", bench_detector.seed, "Seed of the random weights");
  bd->add_flag("--json", bench_detector.json, "Print one JSON object instead of the table");

  ForwardedVerbs forwarded(app);  // train: runs in wingman-train (libtorch), so that wingman starts without it
  TrainingVerbs training(app);    // val, import-halmstad
  LaunchVerbs launching(app);     // fly (with the simulator), demo-camera
  ModelVerbs model_verbs(app);    // model widen-classes
#ifdef WINGMAN_WITH_SIM
  DatasetVerbs dataset(app);    // dataset synth
  ScenarioVerbs scenario(app);  // scenario random
#endif
  // train-recipe, model derive-cfg, dataset mix (after ModelVerbs and DatasetVerbs: `model` and `dataset` exist)
  RecipeVerbs recipe_verbs(app);
  tidy_defaults(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::cerr << "wingman: error: " << e.what() << " (see --help)" << std::endl;
      return 2;
    }
    return app.exit(e);
  }
  if (const int rc = forwarded.run_if_chosen(argc, argv, std::cerr); rc >= 0) return rc;  // returns on failure only
  auto logger = spdlog::stderr_color_st("wingman");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %^%l%$: %v");
  spdlog::set_default_logger(logger);

  try {
    if (*r) {
      if (!replay_quiet) replay.progress = &std::cerr;
      const ReplaySummary summary = run_replay(replay);
      std::cerr << summary.one_line() << std::endl;
      return summary.ok ? 0 : 1;
    }
    if (*s) return run_spy(spy);
    if (const int rc = training.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = launching.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = model_verbs.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = recipe_verbs.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
#ifdef WINGMAN_WITH_SIM
    if (const int rc = dataset.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = scenario.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
#endif
    if (*lo) return run_localize(localize, std::cout, std::cerr);
    if (*pr) return run_predict(predict, std::cout, std::cerr);
    if (*bd) return run_bench_detector_verb(bench_detector, std::cout, std::cerr);
    for (auto [cmd, o, offset, target, quiet] :
         {std::make_tuple(ev, &eval, &eval_offset, &eval_target, eval_quiet),
          std::make_tuple(rp, &report, &report_offset, &report_target, report_quiet)}) {
      if (!*cmd) continue;
      if (!offset->empty() && target->given()) {
        std::cerr << "wingman: error: --formation-offset, or the follower's configuration and the scenario "
                     "(--follower-config, --follower-set, --scenario), not both (see --help)"
                  << std::endl;
        return 2;
      }
      if (!offset->empty()) {
        o->formation_offset_in_world = {(*offset)[0], (*offset)[1], (*offset)[2]};
        o->has_formation = true;
      } else if (target->given()) {
        try {
          o->formation_offset_in_world = formation_offset_for(*target, o->follower_id, o->leader_id);
        } catch (const wingman::common::ConfigError& e) {
          std::cerr << "wingman: error: " << e.what() << std::endl;
          return 2;
        }
        o->has_formation = true;
      }
      if (cmd == ev && o->json_path == "-") {  // --json -: the JSON on stdout, as --json-stdout
        o->json_path.clear();
        eval_json_stdout = true;
      }
      if (!quiet) o->progress = &std::cerr;
      const EvalResult result = evaluate_log(*o);
      if (!o->report_path.empty()) write_html_report(result, *o, o->report_path);
      if (cmd == ev) std::cout << (eval_json_stdout ? result.json() + "\n" : result.report()) << std::flush;
      if (!o->report_path.empty()) std::cerr << "report written to " << o->report_path << std::endl;
    }
    if (*mv) {
      make_video(video);
      std::cerr << "wrote " << video.frames << " frames to " << video.output << std::endl;
    }
    if (*li) {
      const LogSummary summary = summarize_log(info_log, info_snapshot, info_skip_corrupt, &std::cerr);
      std::cout << summary.report() << std::flush;
      if (!info_snapshot.empty() && summary.images_with_pixels > 0)
        std::cout << "last image saved to " << info_snapshot << std::endl;
    }
  } catch (const std::exception& e) {
    std::cerr << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
