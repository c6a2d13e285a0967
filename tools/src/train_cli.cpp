// SPDX-License-Identifier: MIT
// `wingman val`, `wingman import-halmstad` (its options as data: --config, --set, --print-config): command lines over
// the training library (`train`: train_verb.cpp).
#include "wingman/tools/train_cli.hpp"

#include "run_verb.hpp"
#include "verb_layers.hpp"

#include <wingman/common/progress.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/training/halmstad_import.hpp>
#include <wingman/training/sequence_eval.hpp>
#include <wingman/training/val.hpp>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdint>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::tools {

namespace {

/// `wingman import-halmstad`'s options as keys (the seed as an int64_t: the loader's integer).
struct ImportVerbOptions {
  training::HalmstadImportOptions import;
  int64_t seed = static_cast<int64_t>(training::HalmstadImportOptions{}.seed);

  template <class V>
  void visit(V& v) {
    v("input.root", import.root, "the dataset folder (clips.csv, videos/, labels/)");
    v("input.clips", import.clips, "only these clips (names as in clips.csv); [] = all");
    v("input.exclude", import.exclude, "leave out these clips");
    v("sample.frame_step", import.frame_step, "every n-th frame of drone clips");
    v("sample.negative_frame_step", import.negative_frame_step, "every n-th frame of airplane/bird/helicopter clips");
    v("sample.negatives", import.negatives, "include the airplane/bird/helicopter clips");
    v("sample.distractor_classes", import.distractor_classes,
      "label the airplane/bird/helicopter clips' boxes as classes 1, 2, 3 instead of empty negatives");
    v("sample.max_frames_per_clip", import.max_frames_per_clip, "at most this many frames per clip; 0 = all");
    v("split.val_fraction", import.val_fraction, "share of clips in val, per class and distance");
    v("split.seed", seed, "seed of the clip split");
    v("boxes.tighten", import.tighten, "tighten each drone box; false = keep the loose boxes as labelled");
    v("output.dir", import.out_dir, "the YOLO dataset to write");
    v("output.jpeg_quality", import.jpeg_quality, "quality of the written frames, 1..100");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p = named_by_key(import.validate(), {{"root", "input.root"},
                                                                  {"out_dir", "output.dir"},
                                                                  {"frame_step", "sample.frame_step"},
                                                                  {"negative_frame_step", "sample.negative_frame_step"},
                                                                  {"max_frames_per_clip", "sample.max_frames_per_clip"},
                                                                  {"val_fraction", "split.val_fraction"},
                                                                  {"jpeg_quality", "output.jpeg_quality"},
                                                                  {"distractor_classes", "sample.distractor_classes"}});
    if (seed < 0) p.push_back(common::problem("split.seed", static_cast<double>(seed), "must be >= 0"));
    return p;
  }
};

/// `wingman val`'s options as keys: the image metrics (ValOptions) and, with sequences.enabled, the track metrics
/// (SequenceEvalOptions: the data, model and detection keys are shared). The libraries validate their options when
/// they run, naming the fields; here only what the verb needs to start.
struct ValVerbOptions {
  training::ValOptions val = [] {
    training::ValOptions v;
    v.backend = "auto";  // as `wingman predict` and the detector process (one default per flag, issue 34)
    return v;
  }();
  training::SequenceEvalOptions sequences;
  bool sequences_enabled = false;
  int list = 10;
  std::string json;  ///< "" = the table; "-" = the JSON instead; FILE = the table, and the JSON written to FILE

  template <class V>
  void visit(V& v) {
    v("input.data", val.data, "data.yaml or YOLO-layout folder");
    v("input.split", val.split, "split to evaluate; \"\" = a folder's images/");
    v("input.predictions", val.predictions, "instead of model.weights: folder of `wingman predict` <stem>.txt files");
    v("input.class", val.class_id, "class to evaluate (0: drone)");
    v("input.max_images", val.max_images, "evaluate at most this many images; 0 = all");
    v("model.weights", val.weights,
      "Darknet .weights or builtin:wingman-small; \"\" without input.predictions = the shipped model");
    v("model.cfg", val.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
    v("model.backend", val.backend,
      "detector backend: auto (opencl whenever usable, not timed: repeatable), opencl or cpu");
    v("model.input_size", val.input_size, "network input: auto, cfg or WxH");
    v("metrics.conf", val.metrics.conf_thresh, "operating confidence for precision / recall / mean IoU");
    v("metrics.iou", val.metrics.iou_thresh, "IoU match threshold");
    v("metrics.size_edges_px", val.metrics.size_edges_px, "size-bin edges, sqrt(w h) in pixels");
    v("metrics.pr_points", val.metrics.pr_points, "points of the PR curve in the JSON");
    v("metrics.edge_margin_px", val.metrics.edge_margin_px,
      "a truth within this many pixels of the image's border touches the edge");
    val.detection.visit(v);
    v("sequences.enabled", sequences_enabled,
      "track-level metrics of the split's Halmstad clips (input.data: the folder of `wingman import-halmstad`)");
    v("sequences.halmstad_root", sequences.halmstad_root, "the Halmstad dataset (videos/, labels/)");
    v("sequences.localizer_config", sequences.localizer_config,
      "wingman-localizer's YAML; \"\" = its built-in defaults");
    v("sequences.hfov_deg", sequences.hfov_deg, "horizontal field of view of the static camera's pinhole, degrees");
    v("sequences.frame_step", sequences.frame_step, "track every n-th frame (1: every frame)");
    v("sequences.max_seconds", sequences.max_seconds,
      "track only each clip's first this many seconds (0: whole clips; writes no boxes_cache files)");
    v("sequences.clips", sequences.clips, "only these clips of the split; [] = all");
    v("sequences.boxes_cache", sequences.boxes_cache, "folder of each clip's detector boxes (read, or written)");
    sequences.motion.visit(v);  // motion.*: the detector's motion cue over each clip's frames
    // The motion windows' network (the detector's windows.* keys that apply; tracker-driven windows need a tracker
    // that publishes them: not here).
    v("windows.crop_px", sequences.windows.crop_px, "motion.enabled: side of each full-resolution crop, pixels");
    v("windows.p_thresh", sequences.windows.p_thresh, "motion.enabled: confidence threshold inside a crop (0..1)");
    v("windows.gate_sigma", sequences.windows.gate_sigma,
      "motion.enabled: a crop's box must lie within this many sigma_px of the moving blob");
    v("sequences.confirm_within_s", sequences.scoring.confirm_within_s,
      "a drone confirmed this long after its first label counts as in time, s");
    v("sequences.on_target_fraction", sequences.scoring.on_target_fraction,
      "a track is on the drone when more than this share of its confirmed hits is");
    v("output.list", list, "list this many of the largest truths not found, per criterion");
    v("output.json", json, "\"\" = the table; - = one JSON object instead; FILE = the table and the JSON in FILE");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    if (val.data.empty()) p.emplace_back("input.data: give the data (--data, or the key)");
    if (list < 0) p.push_back(common::problem("output.list", list, "must be >= 0"));
    return p;
  }
};

/// Whether `key` (section.name) is in one of `files` (YAML) or `sets` (KEY=VALUE).
bool given_in(const common::ConfigSources& sources, const std::string& section, const std::string& name) {
  for (const auto& set : sources.sets)
    if (set.rfind(section + "." + name + "=", 0) == 0) return true;
  for (const auto& file : sources.files) {
    try {
      const YAML::Node root = YAML::LoadFile(file);
      if (root.IsMap() && root[section].IsMap() && root[section][name]) return true;
    } catch (const YAML::Exception&) {
      // unreadable: the loader has named it already
    }
  }
  return false;
}

}  // namespace

struct TrainingVerbs::State {
  CLI::App* val = nullptr;
  CLI::App* halmstad = nullptr;

  training::ValOptions val_options;
  CLI::Option* val_json = nullptr;  // --json [FILE]
  std::string val_json_path;
  size_t val_list = 10;
  // val --sequences: the track-level metrics (training/sequence_eval.hpp)
  bool val_sequences = false;
  training::SequenceEvalOptions sequences;
  std::unique_ptr<VerbLayers> val_layers;  // val runs with what its layers load; the variables above: the flags

  ImportVerbOptions import_flags;  // what the flags say; the import runs with what its layers load
  bool no_tighten = false, no_negatives = false;
  std::unique_ptr<VerbLayers> import_layers;
};

TrainingVerbs::TrainingVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  State& s = *s_;
  // ---- val ----
  s.val = app.add_subcommand(
      "val", "Detection metrics of a detector (or saved predictions) on a labelled split: AP, PR curve, recall, IoU");
  auto* v = s.val;
  training::ValOptions& vo = s.val_options;
  vo.backend = "auto";  // as `wingman predict` and the detector process (one default per flag, issue 34)
  v->add_option("--data", vo.data, "data.yaml or YOLO-layout folder");
  v->add_option("--split", vo.split, "Split to evaluate (empty: a folder's images/)");
  v->add_option("--weights", vo.weights,
                "Darknet .weights, or builtin:wingman-small: run the detector (Algorithm 2) (empty without "
                "--predictions: the shipped model)");
  v->add_option("--cfg", vo.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
  v->add_option("--backend", vo.backend,
                "Detector backend: auto (opencl whenever usable, not timed: repeatable), opencl or cpu");
  v->add_option("--input-size", vo.input_size,
                "Network input: auto (the cfg's longer side, the other fitted to each image's aspect), cfg or WxH");
  v->add_option("--predictions", vo.predictions, "Instead of --weights: folder of `wingman predict` <stem>.txt files");
  v->add_option("--conf", vo.metrics.conf_thresh, "Operating confidence for precision / recall / mean IoU");
  v->add_option("--iou", vo.metrics.iou_thresh, "IoU match threshold");
  v->add_option("--size-edges", vo.metrics.size_edges_px, "Size-bin edges, sqrt(w h) in pixels")->delimiter(',');
  v->add_option("--pr-points", vo.metrics.pr_points, "Points of the PR curve in the JSON");
  v->add_option("--p-thresh", vo.detection.p_thresh,
                "Detector's confidence floor, low for the curve (not given with --sequences: 0.2, "
                "the detector's p_thresh)");
  v->add_option("--o-thresh", vo.detection.o_thresh, "Detector's NMS IoU threshold");
  v->add_flag("--subsquare", vo.detection.subsquare, "Detect in the centred h x h square of a wide image");
  v->add_flag("--zoom-in", vo.detection.zoom_in, "Re-detect in full-resolution crops (Algorithm 2)");
  v->add_flag("--drone-first", vo.detection.drone_first,
              "Multi-class models: a box whose drone score reaches the threshold is a drone even if another class "
              "scores higher");
  v->add_option("--zoom-max-fraction", vo.detection.zoom_max_fraction,
                "Zoom in only on boxes at most this fraction of the crop's width and height");
  v->add_flag("--flip-fusion", vo.detection.flip_fusion,
              "Also detect in the mirrored image and fuse both passes' boxes (twice the work)");
  v->add_option("--fusion-iou", vo.detection.fusion_iou,
                "--flip-fusion, --coarse-pass: fuse the passes' boxes overlapping above this IoU");
  v->add_flag("--coarse-pass", vo.detection.coarse_pass,
              "Also detect at --coarse-scale of the network input and fuse its large boxes (close drones)");
  v->add_option("--coarse-scale", vo.detection.coarse_scale,
                "--coarse-pass: network input sides times this, multiples of 32");
  v->add_option("--coarse-min-size", vo.detection.coarse_min_size,
                "--coarse-pass: drop its boxes below this sqrt(w h), image pixels");
  v->add_option("--max-detections", vo.detection.max_detections, "At most this many boxes per image");
  v->add_option("--class", vo.class_id, "Class to evaluate (0: drone)");
  v->add_option("--max-images", vo.max_images, "Evaluate at most this many images (0: all)");
  v->add_option("--edge-margin", vo.metrics.edge_margin_px,
                "A truth within this many pixels of the image's border touches the edge");
  v->add_option("--list", s.val_list, "List this many of the largest truths not found, per criterion");
  s.val_json = v->add_option("--json", s.val_json_path,
                             "Alone or --json -: print one JSON object (with the PR curves and every truth not found) "
                             "instead of the table; --json FILE: print the table and write the JSON to FILE")
                   ->expected(0, 1);
  training::SequenceEvalOptions& so = s.sequences;
  v->add_flag(
      "--sequences", s.val_sequences,
      "Track-level metrics: run every frame of the split's Halmstad clips (--data: the folder of `wingman "
      "import-halmstad`, its splits.csv) through the detector and wingman-localizer's tracker; false tracks per "
      "hour, drone clips confirmed and the time to confirm (--conf, --iou, --max-images, --size-edges, "
      "--pr-points, --list do not apply)");
  v->add_option("--halmstad-root", so.halmstad_root, "--sequences: the Halmstad dataset (videos/, labels/)");
  v->add_option("--localizer-config", so.localizer_config,
                "--sequences: wingman-localizer's YAML (config/localizer.yaml keys; camera.* unused) (empty: its "
                "built-in defaults)");
  v->add_option("--hfov-deg", so.hfov_deg,
                "--sequences: horizontal field of view of the static camera's nominal pinhole, degrees");
  v->add_option("--frame-step", so.frame_step, "--sequences: track every n-th frame (1: every frame)");
  v->add_option("--max-seconds", so.max_seconds,
                "--sequences: track only each clip's first this many seconds (0: whole clips; writes no --boxes-cache "
                "files)");
  v->add_option("--clips", so.clips, "--sequences: only these clips of the split (comma-separated)")->delimiter(',');
  v->add_option("--boxes-cache", so.boxes_cache,
                "--sequences: folder of each clip's detector boxes: a clip whose <clip>.boxes is there is tracked "
                "from it without the detector, the others are detected and written (a file made with other "
                "detection settings is an error)");
  v->add_option("--confirm-within", so.scoring.confirm_within_s,
                "--sequences: a drone confirmed this long after its first label counts as in time, s");
  v->add_option("--on-target-fraction", so.scoring.on_target_fraction,
                "--sequences: a track is on the drone when more than this share of its confirmed hits is");
  s.val_layers = std::make_unique<VerbLayers>(v);
  s.val_layers->keys(
      {
          {"--data", "input.data", true},
          {"--split", "input.split", true},
          {"--weights", "model.weights", true},
          {"--cfg", "model.cfg", true},
          {"--backend", "model.backend", true},
          {"--input-size", "model.input_size", true},
          {"--predictions", "input.predictions", true},
          {"--conf", "metrics.conf", false},
          {"--iou", "metrics.iou", false},
          {"--size-edges", "metrics.size_edges_px", false},
          {"--pr-points", "metrics.pr_points", false},
          {"--p-thresh", "detection.p_thresh", false},
          {"--o-thresh", "detection.o_thresh", false},
          {"--subsquare", "detection.subsquare", false},
          {"--zoom-in", "detection.zoom_in", false},
          {"--drone-first", "detection.drone_first", false},
          {"--zoom-max-fraction", "detection.zoom_max_fraction", false},
          {"--flip-fusion", "detection.flip_fusion", false},
          {"--fusion-iou", "detection.fusion_iou", false},
          {"--coarse-pass", "detection.coarse_pass", false},
          {"--coarse-scale", "detection.coarse_scale", false},
          {"--coarse-min-size", "detection.coarse_min_size", false},
          {"--max-detections", "detection.max_detections", false},
          {"--class", "input.class", false},
          {"--max-images", "input.max_images", false},
          {"--edge-margin", "metrics.edge_margin_px", false},
          {"--list", "output.list", false},
          {"--sequences", "sequences.enabled", false},
          {"--halmstad-root", "sequences.halmstad_root", true},
          {"--localizer-config", "sequences.localizer_config", true},
          {"--hfov-deg", "sequences.hfov_deg", false},
          {"--frame-step", "sequences.frame_step", false},
          {"--max-seconds", "sequences.max_seconds", false},
          {"--clips", "sequences.clips", true},
          {"--boxes-cache", "sequences.boxes_cache", true},
          {"--confirm-within", "sequences.confirm_within_s", false},
          {"--on-target-fraction", "sequences.on_target_fraction", false},
      },
      {"--json"});  // output.json: FILE, or - alone

  // ---- import-halmstad ----
  s.halmstad = app.add_subcommand(
      "import-halmstad", "Sample the Halmstad drone videos into a YOLO dataset (split by clip, tightened boxes)");
  auto* h = s.halmstad;
  training::HalmstadImportOptions& io = s.import_flags.import;
  h->add_option("root", io.root, "The dataset folder (clips.csv, videos/, labels/), e.g. ../shared/datasets/halmstad");
  h->add_option("out", io.out_dir, "The YOLO dataset to write");
  h->add_option("--frame-step", io.frame_step, "Every n-th frame of drone clips");
  h->add_option("--negative-frame-step", io.negative_frame_step, "Every n-th frame of airplane/bird/helicopter clips");
  h->add_flag("--no-negatives", s.no_negatives, "Leave out the airplane/bird/helicopter clips");
  h->add_flag("--distractor-classes", io.distractor_classes,
              "Label the airplane/bird/helicopter clips' boxes as classes 1, 2, 3 instead of empty negatives");
  h->add_option("--max-frames-per-clip", io.max_frames_per_clip, "At most this many frames per clip (0: all)");
  h->add_option("--val-fraction", io.val_fraction, "Share of clips in val, per class and distance");
  h->add_option("--seed", io.seed, "Seed of the clip split");
  h->add_flag("--no-tighten", s.no_tighten, "Keep the loose boxes as labelled");
  h->add_option("--clips", io.clips, "Only these clips (comma-separated names)")->delimiter(',');
  h->add_option("--exclude", io.exclude, "Leave out these clips")->delimiter(',');
  h->add_option("--jpeg-quality", io.jpeg_quality, "Quality of the written frames");
  s.import_layers = std::make_unique<VerbLayers>(h);
  s.import_layers->keys(
      {
          {"root", "input.root", true},
          {"out", "output.dir", true},
          {"--frame-step", "sample.frame_step", false},
          {"--negative-frame-step", "sample.negative_frame_step", false},
          {"--distractor-classes", "sample.distractor_classes", false},
          {"--max-frames-per-clip", "sample.max_frames_per_clip", false},
          {"--val-fraction", "split.val_fraction", false},
          {"--seed", "split.seed", false},
          {"--clips", "input.clips", true},
          {"--exclude", "input.exclude", true},
          {"--jpeg-quality", "output.jpeg_quality", false},
      },
      {"--no-negatives", "--no-tighten"});  // sample.negatives and boxes.tighten, false
}

TrainingVerbs::~TrainingVerbs() = default;

int TrainingVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  State& s = *s_;
  if (*s.val) {
    std::vector<std::string> json;  // --json alone or -: the JSON instead of the table; --json FILE: beside it
    if (s.val_json->count() > 0)
      json.push_back("output.json=" + VerbLayers::quoted(s.val_json_path.empty() ? "-" : s.val_json_path));
    int rc = -1;
    const auto loaded = s.val_layers->load_or_exit<ValVerbOptions>(out, err, &rc, json);
    if (!loaded) return rc;
    const bool json_stdout = loaded->json == "-";
    const std::string json_path = json_stdout ? "" : loaded->json;
    if (loaded->sequences_enabled) {
      const bool p_thresh_given = given_in(s.val_layers->sources(), "detection", "p_thresh");
      return run_verb("wingman val", err, [&] {
        training::SequenceEvalOptions so = loaded->sequences;
        const training::ValOptions& vo = loaded->val;
        if (!vo.predictions.empty())
          throw std::invalid_argument("--predictions: --sequences runs the detector on every frame; give --weights");
        if (vo.class_id != 0)
          throw std::invalid_argument(
              fmt::format("--class {}: --sequences tracks class 0 (drone), as wingman-localizer", vo.class_id));
        so.data = vo.data;
        so.split = vo.split;
        so.cfg = vo.cfg;
        if (!vo.weights.empty()) so.weights = vo.weights;
        so.backend = vo.backend;
        so.input_size = vo.input_size;
        so.detection = vo.detection;  // Algorithm 2's flags as given, and the detector's p_thresh unless given
        if (!p_thresh_given) so.detection.p_thresh = detector::DetectorPipelineOptions{}.p_thresh;
        const auto t0 = std::chrono::steady_clock::now();
        std::optional<common::Progress> clips;  // the number of clips is known once the split is read
        const training::SequenceEvalResult r = training::run_sequence_eval(
            so, {}, [&](const std::string& line) { err << "wingman val: " << line << "\n"
                                                       << std::flush; },
            [&](size_t done, size_t total) {
              if (!clips) clips.emplace("wingman val", static_cast<int64_t>(total), "clips", &err);
              clips->update(static_cast<int64_t>(done));
            });
        err << fmt::format("wingman val: {} clips in {:.0f} s\n", r.clips.size(),
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        if (!json_path.empty()) {
          std::ofstream f(json_path);
          f << r.json() << "\n";
          f.close();
          if (!f) throw std::runtime_error(json_path + ": cannot write the JSON");
        }
        out << (json_stdout ? r.json() + "\n" : r.report()) << std::flush;
        return 0;
      });
    }
    return run_verb("wingman val", err, [&] {
      training::ValOptions vo = loaded->val;
      // Neither a model nor saved predictions: the shipped model, as `wingman predict`.
      if (vo.weights.empty() && vo.predictions.empty()) vo.weights = "builtin:wingman-small";
      std::optional<common::Progress> images;  // the number of images is known once the set is read
      const training::DetectionMetrics m = training::run_val(
          vo,
          [&](size_t done, size_t total) {
            if (!images) images.emplace("wingman val", static_cast<int64_t>(total), "images", &err);
            images->update(static_cast<int64_t>(done));
          },
          [&](const std::string& line) { err << "wingman val: " << line << "\n"; });
      if (images) images->finish();
      if (!json_path.empty()) {
        std::ofstream f(json_path);
        f << m.json() << "\n";
        f.close();
        if (!f) throw std::runtime_error(json_path + ": cannot write the JSON");
      }
      out << (json_stdout ? m.json() + "\n" : m.report(static_cast<size_t>(loaded->list))) << std::flush;
      return 0;
    });
  }
  if (*s.halmstad) {
    std::vector<std::string> off;  // the two flags that turn a key off
    if (s.no_negatives) off.emplace_back("sample.negatives=false");
    if (s.no_tighten) off.emplace_back("boxes.tighten=false");
    int rc = -1;
    const auto loaded = s.import_layers->load_or_exit<ImportVerbOptions>(out, err, &rc, off);
    if (!loaded) return rc;
    training::HalmstadImportOptions import = loaded->import;
    import.seed = static_cast<uint64_t>(loaded->seed);
    return run_verb("wingman import-halmstad", err, [&] {
      std::optional<common::Progress> clips;  // the number of clips is known once clips.csv is read
      const training::HalmstadImportSummary summary = training::import_halmstad(
          import, [&](const std::string& line) { err << "wingman import-halmstad: " << line << "\n"; },
          [&](size_t done, size_t total) {
            if (!clips) clips.emplace("wingman import-halmstad", static_cast<int64_t>(total), "clips", &err);
            clips->update(static_cast<int64_t>(done));
          });
      if (clips) clips->finish();
      out << summary.report() << "wrote " << import.out_dir << "/data.yaml\n" << std::flush;
      return 0;
    });
  }
  return -1;
}

}  // namespace wingman::tools
