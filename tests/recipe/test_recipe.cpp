// SPDX-License-Identifier: MIT
// `wingman model derive-cfg` (against tools/train_model.sh's former sed copies of the shipped cfg), training recipes
// (config/training/*.yaml: every problem at once, with file, line and key) and their runner's --dry-run.
#include "../support/test_support.hpp"

#include "wingman/tools/cfg_derive.hpp"
#include "wingman/tools/recipe.hpp"

#include <wingman/common/config.hpp>
#include <wingman/detector/darknet_cfg.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace wingman::tools {
namespace {

using ::testing::HasSubstr;
using wingman::testing::source_path;
using wingman::testing::TempDir;

/// The source tree, without a trailing slash (${src} in the recipes).
std::string src() {
  std::string s = source_path("");
  s.pop_back();
  return s;
}

std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// What `sed ARGS FILE` prints (the reference: tools/train_model.sh's copies until the recipe).
std::string sed(const std::string& args, const std::string& file) {
  std::string text;
  FILE* p = popen(("sed " + args + " '" + file + "'").c_str(), "r");
  if (!p) return "";
  char buf[4096];
  for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) text.append(buf, n);
  pclose(p);
  return text;
}

TEST(CfgDerive, TwoHeadCopyOfTheShippedCfgEqualsTheFormerSedCopy) {
  const std::string cfg = source_path("models/wingman-small.cfg");
  CfgDerivation d;
  d.heads = 2;
  d.anchors = {4, 3, 6, 5, 9, 8, 13, 13, 21, 16, 34, 27};
  const std::string derived = derive_cfg_text(read(cfg), cfg, d);
  EXPECT_EQ(derived, sed("-e '/^# Third head/,$d' -e 's/^anchors=.*/anchors=4,3, 6,5, 9,8, 13,13, 21,16, 34,27/' "
                         "-e 's/^num=9$/num=6/'",
                         cfg));
  const detector::DarknetModel m = detector::parse_darknet_cfg_string(derived);
  ASSERT_EQ(m.heads().size(), 2u);
  EXPECT_EQ(m.layers[static_cast<size_t>(m.heads()[0])].anchors.size(), 12u);

  TempDir tmp;
  std::ofstream(tmp.file("two.cfg")) << derived;
  CfgDerivation size;
  size.width = 416;
  size.height = 416;
  EXPECT_EQ(derive_cfg_text(derived, "two.cfg", size),
            sed("'s/^width=.*/width=416/; s/^height=.*/height=416/'", tmp.file("two.cfg")));
}

TEST(CfgDerive, BoxLossInEveryHeadEqualsTheFormerSedCopy) {
  const std::string cfg = source_path("models/wingman-small.cfg");
  for (const char* normalizer : {"0.75", "1.5", "3"}) {
    CfgDerivation d;
    d.iou_loss = "ciou";
    d.iou_normalizer = normalizer;
    const std::string derived = derive_cfg_text(read(cfg), cfg, d);
    EXPECT_EQ(derived,
              sed(std::string("'s/^\\[yolo\\]$/[yolo]\\niou_loss=ciou\\niou_normalizer=") + normalizer + "/'", cfg))
        << normalizer;
    const detector::DarknetModel m = detector::parse_darknet_cfg_string(derived);
    ASSERT_EQ(m.heads().size(), 3u);
    for (const int h : m.heads()) EXPECT_EQ(m.layers[static_cast<size_t>(h)].iou_loss, "ciou");
  }
}

TEST(CfgDerive, ReplacesAKeyItHasInsteadOfAddingIt) {
  const std::string cfg = source_path("models/wingman-small.cfg");
  CfgDerivation ciou;
  ciou.iou_loss = "ciou";
  ciou.iou_normalizer = "3";
  CfgDerivation giou;
  giou.iou_loss = "giou";
  const std::string twice = derive_cfg_text(derive_cfg_text(read(cfg), cfg, ciou), cfg, giou);
  const detector::DarknetModel m = detector::parse_darknet_cfg_string(twice);
  for (const int h : m.heads()) {
    EXPECT_EQ(m.layers[static_cast<size_t>(h)].iou_loss, "giou");
    EXPECT_FLOAT_EQ(m.layers[static_cast<size_t>(h)].iou_normalizer, 3.0f);
  }
  size_t count = 0;
  for (size_t at = twice.find("iou_loss="); at != std::string::npos; at = twice.find("iou_loss=", at + 1)) ++count;
  EXPECT_EQ(count, 3u);
}

TEST(CfgDerive, RefusesWhatTheCfgCannotGive) {
  const std::string cfg = source_path("models/wingman-small.cfg");
  const std::string text = read(cfg);
  CfgDerivation heads;
  heads.heads = 4;
  EXPECT_THROW(derive_cfg_text(text, cfg, heads), std::invalid_argument);
  CfgDerivation loss;
  loss.iou_loss = "l1";
  EXPECT_THROW(derive_cfg_text(text, cfg, loss), std::invalid_argument);
  CfgDerivation odd;
  odd.anchors = {4, 3, 6};
  EXPECT_THROW(derive_cfg_text(text, cfg, odd), std::invalid_argument);
  // Two anchors for heads whose masks name anchors 0-8: the detector's parser refuses the result.
  CfgDerivation few;
  few.anchors = {4, 3, 6, 5};
  EXPECT_ANY_THROW(derive_cfg_text(text, cfg, few));
}

TEST(Recipe, TheShippedRecipesLoad) {
  const Recipe r = load_recipe(source_path("config/training/wingman-small.yaml"), {}, src());
  std::vector<std::string> names;
  for (const RecipeStage& s : r.stages) names.push_back(s.name);
  EXPECT_THAT(names, ::testing::ElementsAre("stage1", "stage2", "stage3", "stage4", "stage5", "stage6"));
  EXPECT_EQ(r.stage("stage1")->batches, 1500);
  EXPECT_EQ(r.stage("stage6")->batches, 0);  // not run unless set
  EXPECT_EQ(r.dataset("synth")->config, src() + "/config/datasets/synth.yaml");
  const Recipe d = load_recipe(source_path("config/training/wingman-small-distractors.yaml"), {}, src());
  ASSERT_EQ(d.stages.size(), 1u);
  EXPECT_EQ(d.stages[0].widen.classes, 4);
  // The one-class fine-tune with rendered distractors: stage 8's box loss, from the shipped weights, its negatives
  // rendered by the distractor config.
  const Recipe n = load_recipe(source_path("config/training/wingman-small-synth-negatives.yaml"), {}, src());
  ASSERT_EQ(n.stages.size(), 1u);
  EXPECT_EQ(n.stages[0].iou_loss, "ciou");
  EXPECT_THAT(n.stages[0].init, ::testing::ElementsAre(src() + "/models/wingman-small.weights"));
  EXPECT_EQ(n.dataset("synth-negatives")->config, src() + "/config/datasets/distractors_train.yaml");
  // The four-class run with rendered distractors labelled as their classes.
  const Recipe c = load_recipe(source_path("config/training/wingman-small-distractors-synth.yaml"), {}, src());
  ASSERT_EQ(c.stages.size(), 1u);
  EXPECT_EQ(c.stages[0].widen.classes, 4);
  EXPECT_EQ(c.dataset("synth-distractor-classes")->config, src() + "/config/datasets/distractors_train_classes.yaml");
}

TEST(Recipe, SetChangesAStagesKeyOrATopLevelOne) {
  const Recipe r = load_recipe(source_path("config/training/wingman-small.yaml"),
                               {"stage6.batches=800", "stage6.iou_loss=ciou", "stage6.iou_normalizer=1.5",
                                "train.threads=4", "stage2.steps_percent=[40, 60, 80]"});
  EXPECT_EQ(r.stage("stage6")->batches, 800);
  EXPECT_EQ(r.stage("stage6")->iou_loss, "ciou");
  EXPECT_EQ(r.stage("stage6")->iou_normalizer, "1.5");
  EXPECT_EQ(r.train.threads, 4);
  EXPECT_THAT(r.stage("stage2")->steps_percent, ::testing::ElementsAre(40, 60, 80));
  EXPECT_EQ(r.stage("stage5")->batches, 1000);  // the others as in the file
}

TEST(Recipe, ReportsEveryProblemAtOnceWithFileLineAndKey) {
  TempDir tmp;
  const std::string path = tmp.file("bad.yaml");
  std::ofstream(path) << "model: m\n"                          // 1
                         "datasets:\n"                         // 2
                         "  - name: a\n"                       // 3
                         "    kind: synth\n"                   // 4
                         "    config: a.yaml\n"                // 5
                         "    count: many\n"                   // 6
                         "  - name: b\n"                       // 7
                         "    kind: video\n"                   // 8
                         "mixes:\n"                            // 9
                         "  - name: m1\n"                      // 10
                         "    train: [a, c]\n"                 // 11
                         "    val: a\n"                        // 12
                         "    names: [drone]\n"                // 13
                         "stages:\n"                           // 14
                         "  - name: s1\n"                      // 15
                         "    prepare: [a]\n"                  // 16
                         "    cfg: x.cfg\n"                    // 17
                         "    mix: m1\n"                       // 18
                         "    batchez: 100\n"                  // 19
                         "    batches: 4\n"                    // 20
                         "    steps_percent: [50, 80, 90]\n";  // 21
  try {
    load_recipe(path);
    FAIL() << "no error";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_THAT(what, HasSubstr(path + ":6: datasets[0].count: expected an integer"));
    EXPECT_THAT(what, HasSubstr(path + ":8: datasets[1].kind: 'video': expected halmstad, synth or flights"));
    EXPECT_THAT(what, HasSubstr(path + ":11: mixes[0].train: 'c': no such dataset"));
    EXPECT_THAT(what, HasSubstr(path + ":19: stages[0].batchez: unknown key"));
    EXPECT_THAT(what, HasSubstr(path + ":20: stages[0].batches: 4: the rate steps"));
  }
}

TEST(Recipe, AStageMustNotTrainOnADatasetNoStageBeforeItPrepares) {
  TempDir tmp;
  const std::string path = tmp.file("order.yaml");
  std::ofstream(path) << "datasets:\n  - {name: a, kind: synth, config: a.yaml, count: 1}\n"
                         "mixes:\n  - {name: m, train: [a], val: a, names: [drone]}\n"
                         "stages:\n  - {name: s1, cfg: x.cfg, mix: m, batches: 10, steps_percent: [50]}\n"
                         "  - {name: s2, prepare: [a], cfg: x.cfg, mix: m, batches: 10}\n";
  try {
    load_recipe(path);
    FAIL() << "no error";
  } catch (const common::ConfigError& e) {
    EXPECT_THAT(e.what(), HasSubstr("stages[0].mix: 'm' uses a, which neither this stage nor an earlier one prepares"));
  }
}

TEST(DatasetConfigs, TheSynthetic720TrainingSetDiffersFromTheTestSetOnlyInItsSplit) {
  YAML::Node test = YAML::LoadFile(source_path("config/datasets/synth720.yaml"));
  YAML::Node train = YAML::LoadFile(source_path("config/datasets/synth720train.yaml"));
  EXPECT_EQ(test["synth"]["val_fraction"].as<double>(), 1.0);
  EXPECT_EQ(train["synth"]["val_fraction"].as<double>(), 0.0);
  test["synth"].remove("val_fraction");
  train["synth"].remove("val_fraction");
  EXPECT_EQ(YAML::Dump(test), YAML::Dump(train));
}

TEST(RecipeRun, DryRunPrintsTheStagesCommandsAndRunsNothing) {
  TempDir tmp;
  RecipeRunOptions o;
  o.recipe = source_path("config/training/wingman-small.yaml");
  o.src = src();
  o.data = tmp.file("data");
  o.out = tmp.file("out");
  o.bin = "/nonexistent/bin";
  o.dry_run = true;
  o.overrides = {"stage6.batches=800", "stage6.iou_loss=ciou", "stage6.iou_normalizer=3", "stage6.mix=combined-s5",
                 "stage6.out=stage6-ciou-3-s5mix"};
  std::ostringstream out;
  std::ostringstream err;
  EXPECT_EQ(run_recipe(o, out, err), 0);
  const std::string text = out.str();
  EXPECT_THAT(text, HasSubstr("# stage stage1: 1500 iterations into " + o.out + "\n"));
  EXPECT_THAT(text, HasSubstr("# stage stage6: 800 iterations into " + o.out + "/stage6-ciou-3-s5mix\n"));
  EXPECT_THAT(
      text, HasSubstr("/nonexistent/bin/wingman model derive-cfg --cfg " + o.src + "/models/wingman-small.cfg --out " +
                      o.out + "/cfg-ciou-3/wingman-small.cfg --iou-loss ciou --iou-normalizer 3\n"));
  EXPECT_THAT(text, HasSubstr("--out " + o.out + "/stage2 --weights " + o.out + "/wingman-small_final.weights"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("synth720train2")));  // stage 6 on stage 5's mix
  EXPECT_FALSE(std::ifstream(o.data + "/combined.yaml").good());   // nothing written
}

}  // namespace
}  // namespace wingman::tools
