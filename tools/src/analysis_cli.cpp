// SPDX-License-Identifier: MIT
// The analysis verbs' command lines: `wingman localize`, `predict`, `eval`, `report` and `bench detector`, each with
// its options as data (--config FILE, --set KEY=VALUE, --print-config: VerbLayers).
#include "wingman/tools/analysis_cli.hpp"

#include "verb_layers.hpp"
#include "wingman/tools/bench.hpp"
#include "wingman/tools/eval.hpp"
#include "wingman/tools/eval_target.hpp"
#include "wingman/tools/localize.hpp"
#include "wingman/tools/predict.hpp"
#include "wingman/tools/report.hpp"

#include <wingman/common/config.hpp>

#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>

namespace wingman::tools {

namespace {

using common::problem;

/// A visitor that passes every key but `skip` on to `v`.
template <class V>
struct Without {
  V& v;
  std::string_view skip;
  template <class T>
  void operator()(const std::string& key, T& value, const char* doc) {
    if (key != skip) v(key, value, doc);
  }
};

/// `wingman localize`'s options: the box, the calibration and the sphere localizer's keys (as in the localizer's
/// configuration; not target.box_relation: the box is taken as the sphere's).
struct LocalizeVerbOptions {
  LocalizeToolOptions tool;

  template <class V>
  void visit(V& v) {
    v("input.calibration", tool.calibration, "calibration file: ROS camera_info, OpenCV FileStorage or Kalibr");
    v("input.kalibr_camera", tool.kalibr_camera, "camera entry of a Kalibr camchain");
    v("input.box", tool.box, "the box cx, cy, w, h, pixels (origin at the top-left pixel's corner)");
    v("input.image_size", tool.image_size, "WxH of the images the box comes from; \"\" = the calibration's");
    v("input.scale_calibration", tool.scale_calibration,
      "with input.image_size: scale the calibration to that size (a uniform resize) instead of failing");
    Without<V> sphere{v, "target.box_relation"};
    tool.localizer.visit(sphere);
    v("output.json", tool.json, "print one JSON object");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    if (tool.calibration.empty()) p.push_back("input.calibration: give the calibration file (CALIBRATION, or the key)");
    if (tool.box.size() != 4)
      p.push_back(problem("input.box", std::to_string(tool.box.size()) + " numbers", "give 4: cx, cy, w, h"));
    for (const auto& e : tool.localizer.validate()) p.push_back(e);
    return p;
  }
};

/// `wingman predict`'s options: the images, the model, the outputs and the detector's detection.* keys.
struct PredictVerbOptions {
  PredictOptions predict;

  template <class V>
  void visit(V& v) {
    v("input.images", predict.inputs, "image files and/or folders of images");
    v("model.cfg", predict.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
    v("model.weights", predict.weights, "Darknet .weights, or builtin:wingman-small (the shipped model)");
    v("model.backend", predict.backend,
      "inference backend: auto (opencl whenever usable, not timed: repeatable), opencl or cpu");
    v("model.input_size", predict.input_size,
      "network input: auto (the cfg's longer side, the other fitted to each image's aspect), cfg or WxH");
    v("output.dir", predict.out_dir, "output folder for <stem>.txt");
    v("output.draw", predict.draw, "also write <stem>.pred.jpg with the boxes drawn");
    predict.detection.visit(v);
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    if (predict.inputs.empty()) p.push_back("input.images: give at least one image or folder (INPUTS, or the key)");
    if (predict.weights.empty()) p.push_back("model.weights: must be given");
    if (predict.backend != "auto" && predict.backend != "opencl" && predict.backend != "cpu")
      p.push_back(problem("model.backend", predict.backend, "must be auto, opencl or cpu"));
    for (const auto& e : predict.detection.validate()) p.push_back(e);
    return p;
  }
};

/// `wingman bench detector`'s options (the seed as an int64_t: the loader's integer).
struct BenchVerbOptions {
  BenchDetectorOptions bench;
  int64_t seed = BenchDetectorOptions{}.seed;

  template <class V>
  void visit(V& v) {
    v("bench.sizes", bench.sizes, "network input sizes: N (N x N) or WxH, multiples of 32, or cfg (the network's own)");
    v("bench.threads", bench.threads, "OpenCV thread counts; OpenCL: POCL_MAX_PTHREAD_COUNT");
    v("bench.repetitions", bench.repetitions, "timed runs per row");
    v("bench.warmup", bench.warmup, "untimed runs before each row");
    v("bench.pipeline", bench.pipeline, "also time the whole detection pipeline (slow: zoom-in on the CPU)");
    v("bench.layers", bench.layers, "also profile the OpenCL backend per layer");
    v("bench.stream_width", bench.stream_width, "width of the pipeline's synthetic stream, pixels");
    v("bench.stream_height", bench.stream_height, "height of the pipeline's synthetic stream, pixels");
    v("bench.pipeline_max_batch", bench.pipeline_max_batch, "the pipeline's zoom-in crops per forward");
    v("model.cfg", bench.cfg, "network: a .cfg, builtin:tiny-yolo-thesis or builtin:wingman-small");
    v("model.weights", bench.weights, "Darknet .weights or builtin:wingman-small; \"\" = random weights (model.seed)");
    v("model.seed", seed, "seed of the random weights");
    v("output.json", bench.json, "print one JSON object instead of the table");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    for (const auto& e : bench.validate()) p.push_back("bench." + e);  // "sizes = ...": the field is the key's name
    if (seed < 0 || seed > std::numeric_limits<uint32_t>::max())
      p.push_back(problem("model.seed", static_cast<double>(seed), "must be 0..4294967295"));
    return p;
  }
  BenchDetectorOptions options() const {
    BenchDetectorOptions o = bench;
    o.seed = static_cast<uint32_t>(seed);
    return o;
  }
};

/// What `wingman eval` and `wingman report` share: a flight's log read the same way and matched the same way.
struct FlightEvalOptions {
  EvalOptions eval;
  std::vector<double> formation_offset_m;    ///< x, y, z, ENU, metres; empty: none (or from the follower's config)
  std::vector<std::string> follower_config;  ///< the follower's configuration files
  std::vector<std::string> follower_set;     ///< KEY=VALUE over them
  std::string scenario;                      ///< the flight's scenario file ("" = none)
  bool quiet = false;                        ///< no progress on stderr

  template <class V>
  void visit_flight(V& v) {
    v("input.log", eval.log, "LCM log with GROUND_TRUTH and TARGETS (and DETECTIONS_CAM*, IMAGE_CAM0)");
    v("input.truth_channel", eval.truth_channel, "ground_truth_t channel");
    v("input.targets_channel", eval.targets_channel, "targets_t channel");
    v("input.detections_channel", eval.detections_channel,
      "detections_t channels: a regular expression that whole channel names match (a rig: every camera)");
    v("input.image_channel", eval.image_channel, "image_t channel");
    v("input.preview_channel", eval.preview_channel, "the camera's preview (the report's frames without images)");
    v("formation.offset_m", formation_offset_m,
      "desired follower minus leader position x, y, z (ENU), metres; [] = none, or the follower's configuration's");
    v("formation.follower_config", follower_config,
      "the follower's configuration files (a later file wins): the formation error is measured against its target");
    v("formation.follower_set", follower_set, "KEY=VALUE over formation.follower_config (wingman-follower-ctrl --set)");
    v("formation.scenario", scenario, "the flight's scenario file: the vehicles' start for a pid_1d follower");
    v("formation.height_m", eval.formation_height_m, "the follower's constant height, metres; < 0 = the offset's z");
    v("eval.settle_s", eval.settle_s, "skip this many seconds before measuring formation error");
    v("eval.leader_id", eval.leader_id, "vehicle_id of the leader in ground truth");
    v("eval.follower_id", eval.follower_id, "vehicle_id of the camera vehicle");
    v("eval.match_radius_m", eval.match_radius_m, "farther targets are false targets, metres");
    v("eval.range_bins_m", eval.range_bins_m, "upper edges of the range bins, metres, increasing; the last is open");
    v("report.title", eval.title, "report title");
    v("report.frames", eval.report_frames, "camera frames shown in the report");
    v("output.quiet", quiet, "no progress on stderr");
  }
  std::vector<std::string> validate_flight() const {
    std::vector<std::string> p;
    if (eval.log.empty()) p.push_back("input.log: give the flight's LCM log (LOG, or the key)");
    if (eval.truth_channel.empty()) p.push_back("input.truth_channel: must not be empty");
    if (eval.targets_channel.empty()) p.push_back("input.targets_channel: must not be empty");
    if (!(eval.settle_s >= 0.0)) p.push_back(problem("eval.settle_s", eval.settle_s, "must be >= 0 seconds"));
    if (!(eval.match_radius_m > 0.0))
      p.push_back(problem("eval.match_radius_m", eval.match_radius_m, "must be > 0 metres"));
    if (eval.follower_id == eval.leader_id)
      p.push_back(problem("eval.leader_id", eval.leader_id, "must differ from eval.follower_id"));
    for (size_t i = 0; i < eval.range_bins_m.size(); ++i) {
      const double e = eval.range_bins_m[i];
      if (!std::isfinite(e) || e <= 0.0 || (i > 0 && e <= eval.range_bins_m[i - 1])) {
        p.push_back(problem("eval.range_bins_m", e, "each must be finite, > 0 and greater than the one before it"));
        break;
      }
    }
    if (eval.report_frames < 0) p.push_back(problem("report.frames", eval.report_frames, "must be >= 0"));
    if (!formation_offset_m.empty()) {
      bool finite = formation_offset_m.size() == 3;
      for (const double x : formation_offset_m) finite = finite && std::isfinite(x);
      if (!finite) p.push_back("formation.offset_m: must be three finite numbers x, y, z");
      if (!target().given()) return p;
      p.push_back(
          "formation.offset_m: give it, or the follower's configuration and the scenario "
          "(formation.follower_config, follower_set, scenario), not both");
    }
    return p;
  }
  FlightTargetSources target() const {
    FlightTargetSources t;
    t.follower.files = follower_config;
    t.follower.sets = follower_set;
    t.scenario = scenario;
    return t;
  }
};

struct EvalVerbOptions : FlightEvalOptions {
  bool json_stdout = false;  ///< the JSON on stdout instead of the table

  template <class V>
  void visit(V& v) {
    visit_flight(v);
    v("output.json", eval.json_path, "also write the result as JSON to this file; - prints it instead of the table");
    v("output.json_stdout", json_stdout, "print JSON instead of the table (the same as output.json: -)");
    v("output.csv", eval.csv_path, "write the per-target time series (t, track, range, estimate, truth, error)");
    v("output.report", eval.report_path, "write a self-contained HTML report to this file");
  }
  std::vector<std::string> validate() const { return validate_flight(); }
};

struct ReportVerbOptions : FlightEvalOptions {
  template <class V>
  void visit(V& v) {
    visit_flight(v);
    v("output.html", eval.report_path, "HTML file to write");
    v("output.json", eval.json_path, "also write the result as JSON to this file");
    v("output.csv", eval.csv_path, "also write the per-target time series as CSV to this file");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p = validate_flight();
    if (eval.report_path.empty()) p.push_back("output.html: give the HTML file to write (--out, or the key)");
    return p;
  }
};

/// The flags `eval` and `report` share (bound to `o`, whose values --help shows).
void add_eval_options(CLI::App* c, FlightEvalOptions& o) {
  c->add_option("log", o.eval.log, "LCM log with GROUND_TRUTH and TARGETS (and DETECTIONS_CAM0, IMAGE_CAM0)");
  c->add_option("--formation-offset", o.formation_offset_m,
                "Desired follower minus leader position x,y,z (ENU), metres")
      ->expected(3)
      ->delimiter(',');
  c->add_option("--follower-config", o.follower_config,
                "The follower's configuration (wingman-follower-ctrl --config; repeatable, a later file wins): the "
                "formation error is measured against its target (mode formation: formation.offset_m; mode pid_1d: "
                "the leader moved to the follower's starting line, from --scenario)")
      ->allow_extra_args(false)
      ->type_name("FILE");
  c->add_option("--follower-set", o.follower_set,
                "KEY=VALUE over --follower-config, as wingman-follower-ctrl --set (repeatable)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  c->add_option("--scenario", o.scenario,
                "The flight's scenario file (read with wingman-sim's loader): the vehicles' start for a pid_1d "
                "follower (ids --follower-id and --leader-id); with it and no --follower-config, the follower's "
                "built-in defaults are its configuration");
  c->add_option("--formation-height", o.eval.formation_height_m,
                "The follower's constant height, metres (negative: the formation offset's z)");
  c->add_option("--settle", o.eval.settle_s, "Skip this many seconds before measuring formation error");
  c->add_option("--leader-id", o.eval.leader_id, "vehicle_id of the leader in ground truth");
  c->add_option("--follower-id", o.eval.follower_id, "vehicle_id of the camera vehicle");
  c->add_option("--match-radius", o.eval.match_radius_m, "Farther targets are false targets, metres");
  c->add_option("--range-bins", o.eval.range_bins_m,
                "Upper edges of the range bins, metres, increasing; the last bin is open (the default: 0-5, ..., "
                "30+)")
      ->delimiter(',');
  c->add_option("--truth-channel", o.eval.truth_channel, "ground_truth_t channel");
  c->add_option("--targets-channel", o.eval.targets_channel, "targets_t channel");
  c->add_option("--detections-channel", o.eval.detections_channel,
                "detections_t channels: a regular expression that whole channel names match (a rig: every camera)");
  c->add_option("--image-channel", o.eval.image_channel, "image_t channel");
  c->add_option("--title", o.eval.title, "Report title");
  c->add_option("--frames", o.eval.report_frames, "Camera frames shown in the report");
  c->add_flag("--quiet", o.quiet, "No progress on stderr");
}

/// The keys of add_eval_options()'s flags.
const std::tuple<const char*, const char*, bool> kFlightKeys[] = {
    {"log", "input.log", true},
    {"--formation-offset", "formation.offset_m", false},
    {"--follower-config", "formation.follower_config", true},
    {"--follower-set", "formation.follower_set", true},
    {"--scenario", "formation.scenario", true},
    {"--formation-height", "formation.height_m", false},
    {"--settle", "eval.settle_s", false},
    {"--leader-id", "eval.leader_id", false},
    {"--follower-id", "eval.follower_id", false},
    {"--match-radius", "eval.match_radius_m", false},
    {"--range-bins", "eval.range_bins_m", false},
    {"--truth-channel", "input.truth_channel", true},
    {"--targets-channel", "input.targets_channel", true},
    {"--detections-channel", "input.detections_channel", true},
    {"--image-channel", "input.image_channel", true},
    {"--title", "report.title", true},
    {"--frames", "report.frames", false},
    {"--quiet", "output.quiet", false},
};

/// Runs `wingman eval` (`is_eval`) or `wingman report` with the loaded options `v`.
int run_eval_verb(const FlightEvalOptions& v, bool json_stdout, bool is_eval, std::ostream& out, std::ostream& err) {
  EvalOptions o = v.eval;
  if (!v.formation_offset_m.empty()) {
    o.formation_offset_in_world = {v.formation_offset_m[0], v.formation_offset_m[1], v.formation_offset_m[2]};
    o.has_formation = true;
  } else if (v.target().given()) {
    try {
      o.formation_offset_in_world = formation_offset_for(v.target(), o.follower_id, o.leader_id);
    } catch (const common::ConfigError& e) {
      err << "wingman: error: " << e.what() << std::endl;
      return 2;
    }
    o.has_formation = true;
  }
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
  // What the flags say (their defaults are what --help shows); the verbs run with what the layers load.
  CLI::App* localize = nullptr;
  LocalizeVerbOptions localize_flags;
  std::unique_ptr<VerbLayers> localize_layers;
  CLI::App* predict = nullptr;
  PredictVerbOptions predict_flags;
  std::unique_ptr<VerbLayers> predict_layers;
  CLI::App* eval = nullptr;
  EvalVerbOptions eval_flags;
  std::unique_ptr<VerbLayers> eval_layers;
  CLI::App* report = nullptr;
  ReportVerbOptions report_flags;
  std::unique_ptr<VerbLayers> report_layers;
  CLI::App* bench = nullptr;
  BenchDetectorOptions bench_flags;
  std::unique_ptr<VerbLayers> bench_layers;
};

AnalysisVerbs::AnalysisVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  LocalizeToolOptions& localize = s_->localize_flags.tool;
  auto* lo = s_->localize = app.add_subcommand(
      "localize",
      "Localize one box: calibration file + target radius + box -> direction, range, camera-frame position");
  lo->add_option("calibration", localize.calibration,
                 "Calibration file: ROS camera_info, OpenCV FileStorage or Kalibr");
  lo->add_option("--box", localize.box, "Box cx,cy,w,h in pixels (origin at the top-left pixel's corner)")
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
  s_->localize_layers = std::make_unique<VerbLayers>(lo);
  s_->localize_layers->keys({
      {"calibration", "input.calibration", true},
      {"--box", "input.box", false},
      {"--radius", "target.radius_m", false},
      {"--method", "range.method", true},
      {"--min-range", "range.min_m", false},
      {"--max-range", "range.max_m", false},
      {"--edge-noise", "noise.edge_px", false},
      {"--edge-noise-rel", "noise.edge_rel", false},
      {"--centre-noise", "noise.centre_px", false},
      {"--border-margin", "border.margin_px", false},
      {"--kalibr-camera", "input.kalibr_camera", true},
      {"--image-size", "input.image_size", true},
      {"--scale-calibration", "input.scale_calibration", false},
      {"--json", "output.json", false},
  });

  PredictOptions& predict = s_->predict_flags.predict;
  auto* pr = s_->predict = app.add_subcommand(
      "predict", "Run the detector on image files or folders; write YOLO-format labels (and drawn images)");
  pr->add_option("inputs", predict.inputs, "Image files and/or folders of images");
  pr->add_option("--cfg", predict.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
  pr->add_option("--weights", predict.weights,
                 "Darknet .weights, or builtin:wingman-small (the shipped model, models/wingman-small.md)");
  pr->add_option("--backend", predict.backend,
                 "Inference backend: auto (opencl whenever usable, not timed: repeatable), opencl or cpu");
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
  s_->predict_layers = std::make_unique<VerbLayers>(pr);
  s_->predict_layers->keys({
      {"inputs", "input.images", true},
      {"--cfg", "model.cfg", true},
      {"--weights", "model.weights", true},
      {"--backend", "model.backend", true},
      {"--input-size", "model.input_size", true},
      {"--out", "output.dir", true},
      {"--draw", "output.draw", false},
      {"--p-thresh", "detection.p_thresh", false},
      {"--o-thresh", "detection.o_thresh", false},
      {"--subsquare", "detection.subsquare", false},
      {"--zoom-in", "detection.zoom_in", false},
      {"--drone-first", "detection.drone_first", false},
      {"--flip-fusion", "detection.flip_fusion", false},
      {"--fusion-iou", "detection.fusion_iou", false},
      {"--coarse-pass", "detection.coarse_pass", false},
      {"--coarse-scale", "detection.coarse_scale", false},
      {"--coarse-min-size", "detection.coarse_min_size", false},
      {"--policy", "detection.policy", true},
      {"--max-detections", "detection.max_detections", false},
  });

  auto* ev = s_->eval = app.add_subcommand(
      "eval", "Localization, tracking, latency and box errors of a simulated flight's log against its ground truth");
  add_eval_options(ev, s_->eval_flags);
  ev->add_option("--json", s_->eval_flags.eval.json_path,
                 "Also write the result as JSON to this file; - prints it instead of the table");
  ev->add_flag("--json-stdout", s_->eval_flags.json_stdout, "Print JSON instead of the table (the same as --json -)");
  ev->add_option("--csv", s_->eval_flags.eval.csv_path,
                 "Write the per-target time series (t, track, range, estimate, truth, error)");
  ev->add_option("--report", s_->eval_flags.eval.report_path, "Write a self-contained HTML report to this file");
  s_->eval_layers = std::make_unique<VerbLayers>(ev);
  for (const auto& [flag, key, quote] : kFlightKeys) s_->eval_layers->key(flag, key, quote);
  s_->eval_layers->keys({
      {"--json", "output.json", true},
      {"--json-stdout", "output.json_stdout", false},
      {"--csv", "output.csv", true},
      {"--report", "output.report", true},
  });
  auto* rp = s_->report = app.add_subcommand(
      "report", "One self-contained HTML page about a simulated flight: charts and camera frames (opens offline)");
  add_eval_options(rp, s_->report_flags);
  rp->add_option("-o,--out,--output", s_->report_flags.eval.report_path, "HTML file to write");
  rp->add_option("--json", s_->report_flags.eval.json_path, "Also write the result as JSON to this file");
  rp->add_option("--csv", s_->report_flags.eval.csv_path, "Also write the per-target time series as CSV to this file");
  s_->report_layers = std::make_unique<VerbLayers>(rp);
  for (const auto& [flag, key, quote] : kFlightKeys) s_->report_layers->key(flag, key, quote);
  s_->report_layers->keys({
      {"--out", "output.html", true},
      {"--json", "output.json", true},
      {"--csv", "output.csv", true},
  });

  BenchDetectorOptions& bench = s_->bench_flags;
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
  s_->bench_layers = std::make_unique<VerbLayers>(bd);
  s_->bench_layers->keys({
      {"--sizes", "bench.sizes", true},
      {"--threads", "bench.threads", false},
      {"--repetitions", "bench.repetitions", false},
      {"--warmup", "bench.warmup", false},
      {"--cfg", "model.cfg", true},
      {"--weights", "model.weights", true},
      {"--seed", "model.seed", false},
      {"--json", "output.json", false},
  });
}

AnalysisVerbs::~AnalysisVerbs() = default;

int AnalysisVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  int rc = -1;
  try {
    if (*s_->localize) {
      const auto o = s_->localize_layers->load_or_exit<LocalizeVerbOptions>(out, err, &rc);
      return o ? run_localize(o->tool, out, err) : rc;
    }
    if (*s_->predict) {
      const auto o = s_->predict_layers->load_or_exit<PredictVerbOptions>(out, err, &rc);
      return o ? run_predict(o->predict, out, err) : rc;
    }
    if (*s_->bench) {
      const auto o = s_->bench_layers->load_or_exit<BenchVerbOptions>(out, err, &rc);
      return o ? run_bench_detector_verb(o->options(), out, err) : rc;
    }
    if (*s_->eval) {
      const auto o = s_->eval_layers->load_or_exit<EvalVerbOptions>(out, err, &rc);
      return o ? run_eval_verb(*o, o->json_stdout, true, out, err) : rc;
    }
    if (*s_->report) {
      const auto o = s_->report_layers->load_or_exit<ReportVerbOptions>(out, err, &rc);
      return o ? run_eval_verb(*o, false, false, out, err) : rc;
    }
  } catch (const std::exception& e) {
    err << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
  return -1;
}

}  // namespace wingman::tools
