// SPDX-License-Identifier: MIT
// `wingman model widen-classes` and `wingman model box-relation`.
#include "wingman/tools/model_cli.hpp"

#include "run_verb.hpp"

#include "wingman/tools/box_relation_fit.hpp"

#include <wingman/detector/class_widening.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/model_loader.hpp>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace wingman::tools {

namespace fs = std::filesystem;

struct ModelVerbs::State {
  CLI::App* model = nullptr;
  CLI::App* widen = nullptr;
  CLI::App* relation = nullptr;
  BoxRelationRequest rq;
  double max_median_error = -1, max_mad = -1;
  int min_targets = 0;
  std::string cfg = "builtin:wingman-small", weights = "builtin:wingman-small", out_cfg, out_weights, iou_loss;
  float iou_normalizer = 0.0f;
  int classes = 4;
  float bias = detector::kNewClassBias;
};

ModelVerbs::ModelVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  State& s = *s_;
  s.model = app.add_subcommand("model", "Operations on a detector model's .cfg and .weights");
  s.model->require_subcommand(1);
  s.widen = s.model->add_subcommand(
      "widen-classes",
      "Grow a trained model's [yolo] heads to more classes (new classes start at zero weights and a low bias; the "
      "model's drone boxes are unchanged), to fine-tune with distractor classes");
  s.widen->add_option("--cfg", s.cfg, "The trained model's .cfg or builtin:wingman-small");
  s.widen->add_option("--weights", s.weights, "Its .weights or builtin:wingman-small");
  s.widen->add_option("--classes", s.classes, "Classes of the widened heads (4: drone, airplane, bird, helicopter)");
  s.widen->add_option("--new-class-bias", s.bias, "Logit of the new classes' bias (the default: probability 0.01)");
  s.widen->add_option("--iou-loss", s.iou_loss,
                      "Training box loss written into every [yolo] of the new .cfg: mse, giou, diou or ciou (empty: "
                      "the model's)");
  s.widen->add_option("--iou-normalizer", s.iou_normalizer,
                      "Weight of that box loss written into every [yolo] (0: the model's)");
  s.widen->add_option("--out-cfg", s.out_cfg, "The widened .cfg to write")->required();
  s.widen->add_option("--out-weights", s.out_weights, "The widened .weights to write")->required();

  BoxRelationRequest& rq = s.rq;
  s.relation = s.model->add_subcommand(
      "box-relation",
      "Measure how a detector model's boxes relate to the target's bounding sphere on rendered images with known "
      "geometry (`wingman dataset synth`, config/datasets/box_relation.yaml) and write the relation file the "
      "localizer reads (target.box_relation); or --check a relation on other images");
  s.relation->add_option("--data", rq.data, "A `wingman dataset synth` folder (images and meta with sphere_box)")
      ->required();
  s.relation->add_option("--split", rq.split, "Its split");
  s.relation->add_option("--detector-config", rq.detector_config,
                         "The detector's process configuration (empty: its built-in defaults, as installed)");
  s.relation->add_option("--out", rq.out, "Fit: the relation file to write (beside the model's weights)");
  s.relation
      ->add_option("--pass", rq.pass,
                   "single: the single pass's boxes (the relation's main grid); window: each target searched by a "
                   "tracker-driven window as a tracked drone would be (windows.* of the detector configuration, "
                   "enabled or not), the window's boxes (the relation's window grid)")
      ->check(CLI::IsMember({"single", "window"}));
  s.relation->add_option(
      "--base", rq.base,
      "--pass window, fitting: the relation whose main grid is kept (builtin:wingman-small or a file)");
  s.relation->add_option("--check", rq.check,
                         "Evaluate this relation instead of fitting: sphere, builtin:wingman-small or a file");
  s.relation->add_option("--model-name", rq.model_name, "The model's name written into the file");
  s.relation->add_option("--min-iou", rq.min_iou, "A detection is the target's at this IoU with its outline box");
  s.relation->add_option("--max-images", rq.max_images, "At most this many images (0: all)");
  s.relation->add_option(
      "--samples", rq.samples_csv,
      "Also write every matched target (geometry, detected and sphere boxes, ratios, range error, image) to this CSV");
  s.relation->add_option("--max-median-error", s.max_median_error,
                         "Exit 1 when |median range error| over all targets exceeds this (a guard; negative: none)");
  s.relation->add_option("--max-mad", s.max_mad,
                         "Exit 1 when the range error's 1.4826 MAD over all targets exceeds this (negative: none)");
  s.relation->add_option("--min-targets", s.min_targets, "Exit 1 when the detector finds fewer targets than this");
}

ModelVerbs::~ModelVerbs() = default;

int ModelVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  State& s = *s_;
  if (*s.relation) {
    return run_verb("wingman model box-relation", err, [&] {
      s.rq.command_line = fmt::format("wingman model box-relation --data {} --split {}{}{}", s.rq.data, s.rq.split,
                                      s.rq.detector_config.empty() ? "" : " --detector-config " + s.rq.detector_config,
                                      s.rq.pass == "single" ? "" : " --pass " + s.rq.pass + " --base " + s.rq.base);
      const BoxRelationSummary summary = run_box_relation(s.rq, err);
      out << summary.markdown();
      if (s.rq.check.empty()) out << "wrote " << s.rq.out << "\n";
      int rc = 0;
      const RangeErrorStats& all = summary.relation_all;
      if (s.max_median_error >= 0 && std::abs(all.median) > s.max_median_error) {
        err << fmt::format("wingman model box-relation: FAIL: median range error {:+.3f}, bound +-{}\n", all.median,
                           s.max_median_error);
        rc = 1;
      }
      if (s.max_mad >= 0 && all.mad > s.max_mad) {
        err << fmt::format("wingman model box-relation: FAIL: range error MAD {:.3f}, bound {}\n", all.mad, s.max_mad);
        rc = 1;
      }
      if (summary.matched < s.min_targets) {
        err << fmt::format("wingman model box-relation: FAIL: {} targets found, bound {}\n", summary.matched,
                           s.min_targets);
        rc = 1;
      }
      return rc;
    });
  }
  if (!*s.widen) return -1;
  return run_verb("wingman model widen-classes", err, [&] {
    const detector::DarknetModel model = detector::load_model(s.cfg, s.weights);
    detector::DarknetModel wide = detector::widen_classes(model, s.classes, s.bias);
    if (!s.iou_loss.empty() && s.iou_loss != "mse" && s.iou_loss != "giou" && s.iou_loss != "diou" &&
        s.iou_loss != "ciou")
      throw std::invalid_argument(fmt::format("--iou-loss '{}': expected mse, giou, diou or ciou", s.iou_loss));
    if (s.iou_normalizer < 0.0f || !std::isfinite(s.iou_normalizer))
      throw std::invalid_argument(
          fmt::format("--iou-normalizer {}: expected a number > 0 (or 0: the model's)", s.iou_normalizer));
    for (const int h : wide.heads()) {
      if (!s.iou_loss.empty()) wide.layers[static_cast<size_t>(h)].iou_loss = s.iou_loss;
      if (s.iou_normalizer > 0.0f) wide.layers[static_cast<size_t>(h)].iou_normalizer = s.iou_normalizer;
    }
    for (const std::string& path : {s.out_cfg, s.out_weights})
      if (const fs::path parent = fs::path(path).parent_path(); !parent.empty()) fs::create_directories(parent);
    {
      std::ofstream f(s.out_cfg);
      f << "# " << s.cfg << " with its [yolo] heads widened to " << s.classes
        << " classes by `wingman model widen-classes`\n"
        << detector::write_darknet_cfg(wide);
      if (!f.flush()) throw std::runtime_error(fmt::format("{}: cannot write the .cfg", s.out_cfg));
    }
    detector::save_darknet_weights(wide, s.out_weights);
    out << fmt::format("wrote {} and {}: {} heads at {} classes, {} weights\n", s.out_cfg, s.out_weights,
                       wide.heads().size(), s.classes, wide.weight_count());
    return 0;
  });
}

}  // namespace wingman::tools
