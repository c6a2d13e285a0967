// SPDX-License-Identifier: MIT
// The analysis verbs' command lines: `wingman localize`, `predict`, `eval`, `report` and `bench detector`.
#include "wingman/tools/analysis_cli.hpp"

#include "wingman/tools/bench.hpp"
#include "wingman/tools/eval.hpp"
#include "wingman/tools/eval_target.hpp"
#include "wingman/tools/localize.hpp"
#include "wingman/tools/predict.hpp"
#include "wingman/tools/report.hpp"

#include <wingman/common/config.hpp>

#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace wingman::tools {

namespace {

/// `wingman eval` or `wingman report`: the options as the flags give them.
struct EvalVerb {
  CLI::App* app = nullptr;
  EvalOptions options;
  std::vector<double> offset;  ///< --formation-offset x,y,z (ENU, metres), or empty
  FlightTargetSources target;  ///< --follower-config, --follower-set, --scenario
  bool quiet = false;
  bool json_stdout = false;  ///< eval: the JSON on stdout instead of the table
};

/// The options `eval` and `report` share: they read a flight's log the same way.
void add_eval_options(EvalVerb& v) {
  CLI::App* c = v.app;
  EvalOptions& o = v.options;
  c->add_option("log", o.log, "LCM log with GROUND_TRUTH and TARGETS (and DETECTIONS_CAM0, IMAGE_CAM0)")->required();
  c->add_option("--formation-offset", v.offset, "Desired follower minus leader position x,y,z (ENU), metres")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--follower-config", v.target.follower.files,
                "The follower's configuration (wingman-follower-ctrl --config; repeatable, a later file wins): the "
                "formation error is measured against its target (mode formation: formation.offset_m; mode pid_1d: "
                "the leader moved to the follower's starting line, from --scenario)")
      ->allow_extra_args(false)
      ->type_name("FILE");
  c->add_option("--follower-set", v.target.follower.sets,
                "KEY=VALUE over --follower-config, as wingman-follower-ctrl --set (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  c->add_option("--scenario", v.target.scenario,
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
  c->add_flag("--quiet", v.quiet, "No progress on stderr");
}

/// Runs `wingman eval` (`is_eval`) or `wingman report` with the options `v` holds.
int run_eval_verb(EvalVerb& v, bool is_eval, std::ostream& out, std::ostream& err) {
  EvalOptions& o = v.options;
  if (!v.offset.empty() && v.target.given()) {
    err << "wingman: error: --formation-offset, or the follower's configuration and the scenario "
           "(--follower-config, --follower-set, --scenario), not both (see --help)"
        << std::endl;
    return 2;
  }
  if (!v.offset.empty()) {
    o.formation_offset_in_world = {v.offset[0], v.offset[1], v.offset[2]};
    o.has_formation = true;
  } else if (v.target.given()) {
    try {
      o.formation_offset_in_world = formation_offset_for(v.target, o.follower_id, o.leader_id);
    } catch (const common::ConfigError& e) {
      err << "wingman: error: " << e.what() << std::endl;
      return 2;
    }
    o.has_formation = true;
  }
  bool json_stdout = v.json_stdout;
  if (is_eval && o.json_path == "-") {  // --json -: the JSON on stdout, as --json-stdout
    o.json_path.clear();
    json_stdout = true;
  }
  if (!v.quiet) o.progress = &err;
  const EvalResult result = evaluate_log(o);
  if (!o.report_path.empty()) write_html_report(result, o, o.report_path);
  if (is_eval) out << (json_stdout ? result.json() + "\n" : result.report()) << std::flush;
  if (!o.report_path.empty()) err << "report written to " << o.report_path << std::endl;
  return 0;
}

}  // namespace

struct AnalysisVerbs::State {
  CLI::App* localize = nullptr;
  LocalizeToolOptions localize_options;
  CLI::App* predict = nullptr;
  PredictOptions predict_options;
  EvalVerb eval, report;
  CLI::App* bench = nullptr;
  BenchDetectorOptions bench_options;
};

AnalysisVerbs::AnalysisVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  LocalizeToolOptions& localize = s_->localize_options;
  auto* lo = s_->localize = app.add_subcommand(
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

  PredictOptions& predict = s_->predict_options;
  auto* pr = s_->predict = app.add_subcommand(
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

  s_->eval.app = app.add_subcommand(
      "eval", "Localization, tracking, latency and box errors of a simulated flight's log against its ground truth");
  add_eval_options(s_->eval);
  auto* ev = s_->eval.app;
  ev->add_option("--json", s_->eval.options.json_path,
                 "Also write the result as JSON to this file; - prints it instead of the table");
  ev->add_flag("--json-stdout", s_->eval.json_stdout, "Print JSON instead of the table (the same as --json -)");
  ev->add_option("--csv", s_->eval.options.csv_path,
                 "Write the per-target time series (t, track, range, estimate, truth, error)");
  ev->add_option("--report", s_->eval.options.report_path, "Write a self-contained HTML report to this file");
  s_->report.app = app.add_subcommand(
      "report", "One self-contained HTML page about a simulated flight: charts and camera frames (opens offline)");
  add_eval_options(s_->report);
  auto* rp = s_->report.app;
  rp->add_option("-o,--out,--output", s_->report.options.report_path, "HTML file to write")->required();
  rp->add_option("--json", s_->report.options.json_path, "Also write the result as JSON to this file");
  rp->add_option("--csv", s_->report.options.csv_path, "Also write the per-target time series as CSV to this file");

  BenchDetectorOptions& bench = s_->bench_options;
  auto* be = app.add_subcommand("bench", "Benchmarks (numbers, not tests)");
  be->require_subcommand(1);
  auto* bd = s_->bench = be->add_subcommand("detector",
                                            "A network (the thesis network unless --cfg) per frame: OpenCL vs "
                                            "CpuBackend vs bare OpenCV DNN, and the whole pipeline");
  bd->add_option("--sizes", bench.sizes,
                 "Network input sizes: N (N x N) or WxH, multiples of 32, or cfg (the network's own)")
      ->delimiter(',');
  bd->add_option("--threads", bench.threads, "OpenCV thread counts; OpenCL: POCL_MAX_PTHREAD_COUNT")->delimiter(',');
  bd->add_option("--repetitions", bench.repetitions, "Timed runs per row");
  bd->add_option("--warmup", bench.warmup, "Untimed runs before each row");
  bd->add_option("--cfg", bench.cfg,
                 "Network: a .cfg, builtin:tiny-yolo-thesis or builtin:wingman-small (the shipped model)");
  bd->add_option("--weights", bench.weights,
                 "Darknet .weights or builtin:wingman-small (empty: random weights, --seed)");
  bd->add_option("--seed", bench.seed, "Seed of the random weights");
  bd->add_flag("--json", bench.json, "Print one JSON object instead of the table");
}

AnalysisVerbs::~AnalysisVerbs() = default;

int AnalysisVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  try {
    if (*s_->localize) return run_localize(s_->localize_options, out, err);
    if (*s_->predict) return run_predict(s_->predict_options, out, err);
    if (*s_->bench) return run_bench_detector_verb(s_->bench_options, out, err);
    if (*s_->eval.app) return run_eval_verb(s_->eval, true, out, err);
    if (*s_->report.app) return run_eval_verb(s_->report, false, out, err);
  } catch (const std::exception& e) {
    err << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
  return -1;
}

}  // namespace wingman::tools
