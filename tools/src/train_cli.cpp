// SPDX-License-Identifier: MIT
// `wingman train`, `wingman val`, `wingman import-halmstad`: command lines over the training library.
#include "wingman/tools/train_cli.hpp"

#include "run_verb.hpp"

#include <wingman/common/progress.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/training/halmstad_import.hpp>
#include <wingman/training/sequence_eval.hpp>
#include <wingman/training/train_options.hpp>
#include <wingman/training/val.hpp>
#ifdef WINGMAN_WITH_TRAINING
#include <wingman/training/trainer.hpp>
#endif

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <unistd.h>

namespace wingman::tools {

namespace {

#ifdef WINGMAN_WITH_TRAINING
std::atomic<bool> g_stop{false};

extern "C" void on_interrupt(int) {
  if (g_stop.load()) std::_Exit(130);  // a second Ctrl-C: leave at once
  g_stop = true;
}

/// OpenMP (libtorch's threads) and OpenBLAS read OMP_WAIT_POLICY and OPENBLAS_NUM_THREADS once, when they load:
/// busy-waiting OpenMP threads and OpenBLAS threads inside them halve the training speed on a 2-core machine
/// (measured: docs/training.md). When neither is set, set OMP_WAIT_POLICY=PASSIVE and OPENBLAS_NUM_THREADS=1
/// and restart this process once with the same arguments (Linux: /proc/self/exe and /proc/self/cmdline).
/// Returns (and trains as it is) when they are set or the restart is not possible.
void restart_with_thread_settings(std::ostream& err) {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("OPENBLAS_NUM_THREADS") || std::getenv("WINGMAN_TRAIN_RESTARTED"))
    return;
  std::ifstream cmdline("/proc/self/cmdline", std::ios::binary);
  std::vector<std::string> args;
  for (std::string a; std::getline(cmdline, a, '\0');) args.push_back(a);
  if (args.empty()) return;
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  setenv("OMP_WAIT_POLICY", "PASSIVE", 1);
  setenv("OPENBLAS_NUM_THREADS", "1", 1);
  setenv("WINGMAN_TRAIN_RESTARTED", "1", 1);
  err << "wingman train: restarting with OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1 (set them to choose)\n"
      << std::flush;
  execv("/proc/self/exe", argv.data());
  err << "wingman train: note: could not restart (" << std::strerror(errno) << "); training without them\n";
}
#endif

}  // namespace

struct TrainingVerbs::State {
  CLI::App* train = nullptr;
  CLI::App* val = nullptr;
  CLI::App* halmstad = nullptr;

  // train: the .cfg's [net] keys give the defaults of the fields it has; only options given on the command line
  // override them. The other fields, and the defaults --help shows, are TrainOptions's own.
  std::string cfg, data;
  training::TrainOptions given;
  std::vector<std::pair<CLI::Option*, std::function<void(training::TrainOptions&)>>> overrides;

  training::ValOptions val_options;
  CLI::Option* val_json = nullptr;  // --json [FILE]
  std::string val_json_path;
  CLI::Option* val_p_thresh = nullptr;
  CLI::Option* val_predictions = nullptr;
  CLI::Option* val_class = nullptr;
  size_t val_list = 10;
  // val --sequences: the track-level metrics (training/sequence_eval.hpp)
  bool val_sequences = false;
  training::SequenceEvalOptions sequences;

  training::HalmstadImportOptions import;
  bool no_tighten = false, no_negatives = false;
};

TrainingVerbs::TrainingVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  State& s = *s_;
  using training::TrainOptions;
  // ---- train ----
  s.train = app.add_subcommand(
      "train", "Train a Darknet .cfg network on a YOLO dataset (libtorch); writes .weights the detector loads");
  auto* t = s.train;
  t->add_option("--cfg", s.cfg, "Darknet .cfg: the network and, in [net], its training settings")->required();
  t->add_option("--data", s.data, "data.yaml or YOLO-layout folder (images/<split>, labels/<split>)")->required();
  TrainOptions& g = s.given;
  t->add_option("--out", g.out_dir, "Output folder: checkpoint.pt, <cfg stem>_{last,final,N}.weights");
  t->add_flag("--resume", g.resume, "Continue from <out>/checkpoint.pt (same cfg, data, seed and batch)");
  t->add_option("--weights", g.init_weights, "Start from these Darknet .weights instead of random weights");
  t->add_flag("--partial-weights", g.init_partial,
              "--weights may hold only the first convolutional layers (a trained network the cfg extends with "
              "appended layers): those are loaded, the others start random");
  t->add_option("--train-split", g.train_split, "Split to train on");
  t->add_option("--val-split", g.val_split, "Split to validate on at the end (empty: none)");
  t->add_option("--val-max-images", g.val_max_images, "Validate on at most this many images (0: all)");
  t->add_option("--seed", g.seed, "Seed of the initial weights, data order and augmentation");
  t->add_option("--threads", g.threads, "libtorch threads");
  t->add_option("--checkpoint-interval", g.checkpoint_interval, "Checkpoint every this many iterations");
  t->add_option("--weights-interval", g.weights_interval,
                "Keep <stem>_<iteration>.weights every this many iterations (0: never)");
  t->add_option("--log-interval", g.log_interval, "Print progress every this many iterations");
  t->add_option("--ema-decay", g.ema.decay,
                "Keep an exponential moving average of the weights with this decay (e.g. 0.99: about the last 100 "
                "iterations) and export it; <stem>_raw_final.weights keeps the trained weights (0: none)");
  t->add_option("--ema-ramp", g.ema.ramp, "The average's decay rises to --ema-decay over about this many iterations");
  // The [net] keys: given, the option wins; not given, the cfg's key if it has it, else the default shown.
  auto over = [&](CLI::Option* o, std::function<void(TrainOptions&)> apply) { s.overrides.emplace_back(o, apply); };
  over(t->add_option("--batch", g.batch, "Images per iteration (not given: [net] batch if set)"),
       [&g](TrainOptions& o) { o.batch = g.batch; });
  over(t->add_option("--subdivisions", g.subdivisions, "Passes per iteration (not given: [net] subdivisions if set)"),
       [&g](TrainOptions& o) { o.subdivisions = g.subdivisions; });
  over(t->add_option("--max-batches", g.max_batches, "Iterations to train (not given: [net] max_batches if set)"),
       [&g](TrainOptions& o) { o.max_batches = g.max_batches; });
  over(t->add_option("--learning-rate", g.lr.base,
                     "Learning rate after warm-up (not given: [net] learning_rate if set)"),
       [&g](TrainOptions& o) { o.lr.base = g.lr.base; });
  over(t->add_option("--burn-in", g.lr.burn_in, "Warm-up iterations (not given: [net] burn_in if set)"),
       [&g](TrainOptions& o) { o.lr.burn_in = g.lr.burn_in; });
  over(t->add_option("--steps", g.lr.steps, "Iterations of the rate steps (not given: [net] steps if set)")
           ->delimiter(','),
       [&g](TrainOptions& o) { o.lr.steps = g.lr.steps; });
  over(t->add_option("--scales", g.lr.scales, "Factor at each step (not given: [net] scales if set)")->delimiter(','),
       [&g](TrainOptions& o) { o.lr.scales = g.lr.scales; });
  over(t->add_option("--momentum", g.momentum, "SGD momentum (not given: [net] momentum if set)"),
       [&g](TrainOptions& o) { o.momentum = g.momentum; });
  over(t->add_option("--decay", g.decay, "Weight decay (not given: [net] decay if set)"),
       [&g](TrainOptions& o) { o.decay = g.decay; });
  over(t->add_option("--hue", g.augment.hue, "Hue jitter r_h (not given: [net] hue if set)"),
       [&g](TrainOptions& o) { o.augment.hue = g.augment.hue; });
  over(
      t->add_option("--saturation", g.augment.saturation, "Saturation jitter r_s (not given: [net] saturation if set)"),
      [&g](TrainOptions& o) { o.augment.saturation = g.augment.saturation; });
  over(t->add_option("--exposure", g.augment.exposure, "Value jitter r_v (not given: [net] exposure if set)"),
       [&g](TrainOptions& o) { o.augment.exposure = g.augment.exposure; });
  over(t->add_option("--jitter", g.augment.jitter, "Random crop r_c (not given: [net] jitter, else the head's jitter)")
           ->default_str(""),
       [&g](TrainOptions& o) { o.augment.jitter = g.augment.jitter; });
  over(t->add_option("--flip", g.augment.flip, "Horizontal flip probability (not given: [net] flip=0: 0)"),
       [&g](TrainOptions& o) { o.augment.flip = g.augment.flip; });
  over(t->add_option("--scale", g.augment.scale, "Extra zoom range: factor in [1/(1+s), 1+s]"),
       [&g](TrainOptions& o) { o.augment.scale = g.augment.scale; });
  over(t->add_option("--translate", g.augment.translate, "Extra shift, fraction of the crop"),
       [&g](TrainOptions& o) { o.augment.translate = g.augment.translate; });
  over(t->add_option("--blur", g.augment.blur, "Probability of a Gaussian blur"),
       [&g](TrainOptions& o) { o.augment.blur = g.augment.blur; });
  over(t->add_option("--noise", g.augment.noise, "Probability of pixel noise"),
       [&g](TrainOptions& o) { o.augment.noise = g.augment.noise; });
  over(t->add_option("--mosaic", g.augment.mosaic,
                     "Probability of a 2x2 mosaic sample (not given: [net] mosaic=1: 0.5)"),
       [&g](TrainOptions& o) { o.augment.mosaic = g.augment.mosaic; });

  // ---- val ----
  s.val = app.add_subcommand(
      "val", "Detection metrics of a detector (or saved predictions) on a labelled split: AP, PR curve, recall, IoU");
  auto* v = s.val;
  training::ValOptions& vo = s.val_options;
  vo.backend = "auto";  // as `wingman predict` and the detector process (one default per flag, issue 34)
  v->add_option("--data", vo.data, "data.yaml or YOLO-layout folder")->required();
  v->add_option("--split", vo.split, "Split to evaluate (empty: a folder's images/)");
  v->add_option("--weights", vo.weights,
                "Darknet .weights, or builtin:wingman-small: run the detector (Algorithm 2) (empty without "
                "--predictions: the shipped model)");
  v->add_option("--cfg", vo.cfg, "Darknet .cfg, builtin:wingman-small or builtin:tiny-yolo-thesis");
  v->add_option("--backend", vo.backend, "Detector backend: auto, opencl or cpu");
  v->add_option("--input-size", vo.input_size,
                "Network input: auto (the cfg's longer side, the other fitted to each image's aspect), cfg or WxH");
  s.val_predictions = v->add_option("--predictions", vo.predictions,
                                    "Instead of --weights: folder of `wingman predict` <stem>.txt files");
  v->add_option("--conf", vo.metrics.conf_thresh, "Operating confidence for precision / recall / mean IoU");
  v->add_option("--iou", vo.metrics.iou_thresh, "IoU match threshold");
  v->add_option("--size-edges", vo.metrics.size_edges_px, "Size-bin edges, sqrt(w h) in pixels")->delimiter(',');
  v->add_option("--pr-points", vo.metrics.pr_points, "Points of the PR curve in the JSON");
  s.val_p_thresh = v->add_option("--p-thresh", vo.detection.p_thresh,
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
  s.val_class = v->add_option("--class", vo.class_id, "Class to evaluate (0: drone)");
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
  v->add_option("--clips", so.clips, "--sequences: only these clips of the split (comma-separated)")->delimiter(',');
  v->add_option("--boxes-cache", so.boxes_cache,
                "--sequences: folder of each clip's detector boxes: a clip whose <clip>.boxes is there is tracked "
                "from it without the detector, the others are detected and written (a file made with other "
                "detection settings is an error)");
  v->add_option("--confirm-within", so.scoring.confirm_within_s,
                "--sequences: a drone confirmed this long after its first label counts as in time, s");
  v->add_option("--on-target-fraction", so.scoring.on_target_fraction,
                "--sequences: a track is on the drone when more than this share of its confirmed hits is");

  // ---- import-halmstad ----
  s.halmstad = app.add_subcommand(
      "import-halmstad", "Sample the Halmstad drone videos into a YOLO dataset (split by clip, tightened boxes)");
  auto* h = s.halmstad;
  training::HalmstadImportOptions& io = s.import;
  h->add_option("root", io.root, "The dataset folder (clips.csv, videos/, labels/), e.g. ../shared/datasets/halmstad")
      ->required();
  h->add_option("out", io.out_dir, "The YOLO dataset to write")->required();
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
}

TrainingVerbs::~TrainingVerbs() = default;

int TrainingVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  State& s = *s_;
  if (*s.val && s.val_sequences) {
    return run_verb("wingman val", err, [&] {
      training::SequenceEvalOptions so = s.sequences;
      const training::ValOptions& vo = s.val_options;
      if (s.val_predictions->count() > 0)
        throw std::invalid_argument("--predictions: --sequences runs the detector on every frame; give --weights");
      if (s.val_class->count() > 0 && vo.class_id != 0)
        throw std::invalid_argument(
            fmt::format("--class {}: --sequences tracks class 0 (drone), as wingman-localizer", vo.class_id));
      so.data = vo.data;
      so.split = vo.split;
      so.cfg = vo.cfg;
      if (!vo.weights.empty()) so.weights = vo.weights;
      so.backend = vo.backend;
      so.input_size = vo.input_size;
      so.detection = vo.detection;  // Algorithm 2's flags as given, and the detector's p_thresh unless given
      if (s.val_p_thresh->count() == 0) so.detection.p_thresh = detector::DetectorPipelineOptions{}.p_thresh;
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
      const bool json_stdout = s.val_json->count() > 0 && (s.val_json_path.empty() || s.val_json_path == "-");
      if (!json_stdout && !s.val_json_path.empty()) {
        std::ofstream f(s.val_json_path);
        f << r.json() << "\n";
        f.close();
        if (!f) throw std::runtime_error(s.val_json_path + ": cannot write the JSON");
      }
      out << (json_stdout ? r.json() + "\n" : r.report()) << std::flush;
      return 0;
    });
  }
  if (*s.val) {
    return run_verb("wingman val", err, [&] {
      // Neither a model nor saved predictions: the shipped model, as `wingman predict`.
      if (s.val_options.weights.empty() && s.val_options.predictions.empty())
        s.val_options.weights = "builtin:wingman-small";
      std::optional<common::Progress> images;  // the number of images is known once the set is read
      const training::DetectionMetrics m = training::run_val(
          s.val_options,
          [&](size_t done, size_t total) {
            if (!images) images.emplace("wingman val", static_cast<int64_t>(total), "images", &err);
            images->update(static_cast<int64_t>(done));
          },
          [&](const std::string& line) { err << "wingman val: " << line << "\n"; });
      if (images) images->finish();
      const bool json_stdout = s.val_json->count() > 0 && (s.val_json_path.empty() || s.val_json_path == "-");
      if (!json_stdout && !s.val_json_path.empty()) {
        std::ofstream f(s.val_json_path);
        f << m.json() << "\n";
        f.close();
        if (!f) throw std::runtime_error(s.val_json_path + ": cannot write the JSON");
      }
      out << (json_stdout ? m.json() + "\n" : m.report(s.val_list)) << std::flush;
      return 0;
    });
  }
  if (*s.halmstad) {
    s.import.tighten = !s.no_tighten;
    s.import.negatives = !s.no_negatives;
    return run_verb("wingman import-halmstad", err, [&] {
      std::optional<common::Progress> clips;  // the number of clips is known once clips.csv is read
      const training::HalmstadImportSummary summary = training::import_halmstad(
          s.import, [&](const std::string& line) { err << "wingman import-halmstad: " << line << "\n"; },
          [&](size_t done, size_t total) {
            if (!clips) clips.emplace("wingman import-halmstad", static_cast<int64_t>(total), "clips", &err);
            clips->update(static_cast<int64_t>(done));
          });
      if (clips) clips->finish();
      out << summary.report() << "wrote " << s.import.out_dir << "/data.yaml\n" << std::flush;
      return 0;
    });
  }
  if (*s.train) {
#ifndef WINGMAN_WITH_TRAINING
    err << "wingman train: error: this build has no trainer: install libtorch-dev (Debian) and configure with "
           "-DWINGMAN_WITH_TRAINING=ON\n";
    return 1;
#else
    training::TrainOptions o;
    // The .cfg gives the defaults; a cfg that does not parse is reported as every other failure of the verb.
    const int cfg_rc = run_verb("wingman train", err, [&] {
      const detector::DarknetModel model = detector::parse_darknet_cfg(s.cfg);
      o = training::train_options_from_model(model, s.cfg);
      const std::string note = training::multi_scale_note(model);
      if (!note.empty()) err << "wingman train: note: " << note << "\n";
      return 0;
    });
    if (cfg_rc != 0) return cfg_rc;
    const training::TrainOptions& g = s.given;
    o.data = s.data;
    o.out_dir = g.out_dir;
    o.init_weights = g.init_weights;
    o.init_partial = g.init_partial;
    o.resume = g.resume;
    o.train_split = g.train_split;
    o.val_split = g.val_split;
    o.val_max_images = g.val_max_images;
    o.seed = g.seed;
    o.threads = g.threads;
    o.checkpoint_interval = g.checkpoint_interval;
    o.weights_interval = g.weights_interval;
    o.log_interval = g.log_interval;
    o.ema = g.ema;
    for (auto& [option, apply] : s.overrides)
      if (option->count() > 0) apply(o);
    restart_with_thread_settings(err);
    return run_verb("wingman train", err, [&] {
      training::Trainer trainer(o);
      err << fmt::format(
          "wingman train: {} training images, batch {} in {} subdivisions, {} iterations from {}; "
          "Ctrl-C writes a checkpoint and stops\n",
          trainer.train_images(), o.batch, o.subdivisions, o.max_batches, trainer.iteration());
      if (o.init_partial && !o.resume)
        err << fmt::format("wingman train: the first {} convolutional layers from {}; the others start random\n",
                           trainer.init_layers(), o.init_weights);
      const std::string log_path = (std::filesystem::path(o.out_dir) / "progress.csv").string();
      const bool fresh = !std::filesystem::exists(log_path);
      std::ofstream log(log_path, std::ios::app);
      if (fresh) log << "iteration,loss,loss_avg,coord,object,noobject,cls,mean_iou,learning_rate,images_per_s\n";
      g_stop = false;
      std::signal(SIGINT, on_interrupt);
      std::signal(SIGTERM, on_interrupt);
      const training::TrainSummary summary = trainer.run(
          [&](const training::TrainProgress& p) {
            err << "wingman train: " << p.one_line() << "\n" << std::flush;
            log << fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.4f},{:.6g},{:.3f}\n", p.iteration,
                               p.loss, p.loss_avg, p.coord, p.object, p.noobject, p.cls, p.mean_iou, p.learning_rate,
                               p.images_per_s)
                << std::flush;
          },
          &g_stop);
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
      out << summary.report() << std::flush;
      return summary.interrupted ? 130 : 0;
    });
#endif
  }
  return -1;
}

}  // namespace wingman::tools
