// SPDX-License-Identifier: MIT
// `wingman train`: the command line over the trainer (training/trainer.hpp), run by wingman-train.
#include "train_verb.hpp"

#include "run_verb.hpp"

#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/training/train_options.hpp>
#ifdef WINGMAN_WITH_TRAINING
#include <wingman/training/trainer.hpp>
#endif

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <utility>
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

struct TrainVerb::State {
  CLI::App* train = nullptr;

  // The .cfg's [net] keys give the defaults of the fields it has; only options given on the command line override
  // them. The other fields, and the defaults --help shows, are TrainOptions's own.
  std::string cfg, data;
  training::TrainOptions given;
  std::vector<std::pair<CLI::Option*, std::function<void(training::TrainOptions&)>>> overrides;
};

TrainVerb::TrainVerb(CLI::App& app) : s_(std::make_unique<State>()) {
  State& s = *s_;
  using training::TrainOptions;
  s.train = app.add_subcommand("train", kTrainVerbDescription);
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
}

TrainVerb::~TrainVerb() = default;

int TrainVerb::run_if_chosen(std::ostream& out, std::ostream& err) {
  State& s = *s_;
  if (!*s.train) return -1;
#ifndef WINGMAN_WITH_TRAINING
  (void)out;
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
          log << fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.4f},{:.6g},{:.3f}\n", p.iteration, p.loss,
                             p.loss_avg, p.coord, p.object, p.noobject, p.cls, p.mean_iou, p.learning_rate,
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

}  // namespace wingman::tools
