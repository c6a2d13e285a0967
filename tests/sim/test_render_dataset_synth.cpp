// SPDX-License-Identifier: MIT
// `wingman dataset synth`: the YOLO layout as the trainer reads it, labels that are the exact truth boxes of what the
// metadata describes, determinism per seed, progress, and errors.
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/sim/distractor_model.hpp>
#include <wingman/sim/truth_box.hpp>
#include <wingman/tools/box_relation_fit.hpp>
#include <wingman/tools/dataset_synth.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;

/// A small, quick configuration: 320x240 images, two cameras, half of the images in val.
std::string write_config(const wingman::testing::TempDir& dir, const std::string& extra = "") {
  const std::string path = dir.file("synth.yaml");
  std::ofstream(path) << "synth:\n  width: 320\n  height: 240\n  cameras: 2\n  val_fraction: 0.5\n"
                      << "  blur_fraction: 0.3\n"
                      << extra;
  return path;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Every file under `root`, relative path -> bytes.
std::map<std::string, std::string> all_files(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file()) files[fs::relative(entry.path(), root).string()] = read_file(entry.path());
  }
  return files;
}

/// A metadata file, parsed.
nlohmann::json read_meta(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

Eigen::Isometry3d pose(const nlohmann::json& node) {
  const auto p = node.at("p").get<std::vector<double>>(), q = node.at("q_wxyz").get<std::vector<double>>();
  EXPECT_EQ(p.size(), 3u);
  EXPECT_EQ(q.size(), 4u);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(p.at(0), p.at(1), p.at(2));
  T.linear() = Eigen::Quaterniond(q.at(0), q.at(1), q.at(2), q.at(3)).normalized().toRotationMatrix();
  return T;
}

/// A config section "drone:" holding a DroneSpec.
struct DroneSection {
  sim::DroneSpec drone;
  template <class V>
  void visit(V& v) {
    drone.visit(v);
  }
  std::vector<std::string> validate() const { return drone.validate(); }
};

/// The DroneSpec written in a metadata file's target.spec, read back through the config loader.
sim::DroneSpec spec_from(const nlohmann::json& node) {
  // JSON is YAML (flow style): the spec object goes to the config loader as written.
  return common::load_options_from_string<DroneSection>("drone: " + node.dump(), "metadata spec").drone;
}

/// The camera an image's metadata describes.
geometry::CameraModel camera_of(const nlohmann::json& meta, int width, int height) {
  const nlohmann::json& c = meta.at("camera");
  const geometry::Distortion distortion = c.at("distortion_model").get<std::string>() == "equidistant"
                                              ? geometry::Distortion::kEquidistant
                                              : geometry::Distortion::kRadTan;
  return geometry::CameraModel(width, height, c.at("fx").get<double>(), c.at("fy").get<double>(),
                               c.at("cx").get<double>(), c.at("cy").get<double>(), distortion,
                               c.at("coefficients").get<std::vector<double>>());
}

TEST(DatasetSynth, WritesAYoloDatasetWhoseLabelsAreTheTruthBoxesOfItsMetadata) {
  wingman::testing::TempDir dir;
  DatasetSynthRequest request;
  request.out_dir = dir.file("set");
  request.count = 6;
  request.seed = 3;
  request.config = write_config(dir);
  if (sim::test::missing_shared("meshes").empty()) request.meshes = {sim::test::shared_path("meshes/dji_f450.glb")};
  std::ostringstream progress;
  const DatasetSynthSummary summary = run_dataset_synth(request, progress);
  EXPECT_EQ(summary.images, 6);
  EXPECT_EQ(summary.train + summary.val, 6);
  // Progress (common::Progress) only for a job of 5 s or more: then its closing line.
  EXPECT_TRUE(progress.str().empty() ||
              progress.str().find("wingman dataset synth: 6/6 images (100.0 %)") != std::string::npos)
      << progress.str();
  EXPECT_NE(summary.one_line().find("wrote 6 images"), std::string::npos);

  // The trainer's reader takes it as it is.
  size_t images = 0;
  for (const char* split : {"train", "val"}) {
    if ((split == std::string("val") ? summary.val : summary.train) == 0) continue;
    const training::YoloDataset set = training::load_yolo_dataset(request.out_dir + "/data.yaml", split);
    EXPECT_EQ(set.class_names, std::vector<std::string>{"drone"});
    for (const training::DatasetImage& image : set.images) {
      ++images;
      ASSERT_EQ(image.boxes.size(), 1u) << image.image_path << ": one drone per image";
      const cv::Mat pixels = cv::imread(image.image_path);
      ASSERT_EQ(pixels.cols, 320);
      ASSERT_EQ(pixels.rows, 240);
      // The metadata: camera, poses, airframe; the label is the truth box of that scene.
      const fs::path stem = fs::path(image.image_path).stem();
      const nlohmann::json meta = read_meta(request.out_dir + "/meta/" + split + "/" + stem.string() + ".json");
      const geometry::CameraModel camera = camera_of(meta, 320, 240);
      const nlohmann::json& target = meta.at("target");
      const sim::DroneSpec spec = spec_from(target.at("spec"));
      const sim::DroneModel drone = sim::DroneModel::from_spec(spec);
      EXPECT_NEAR(drone.bounding_radius(), target.at("bounding_radius_m").get<double>(), 1e-6);
      const sim::RenderedBox truth = sim::TruthBoxProjector(camera).project(drone, pose(meta.at("T_cam_to_world")),
                                                                            pose(target.at("T_body_to_world")),
                                                                            target.at("prop_angle_rad").get<double>());
      ASSERT_TRUE(truth.visible) << image.image_path;
      const training::LabeledBox& label = image.boxes[0];
      EXPECT_EQ(label.cls, 0);
      EXPECT_NEAR(label.cx * 320.0, truth.cx, 1e-3) << image.image_path;
      EXPECT_NEAR(label.cy * 240.0, truth.cy, 1e-3) << image.image_path;
      EXPECT_NEAR(label.w * 320.0, truth.w, 1e-3) << image.image_path;
      EXPECT_NEAR(label.h * 240.0, truth.h, 1e-3) << image.image_path;
      const double range = target.at("range_m").get<double>();
      EXPECT_GE(range, 1.0);
      EXPECT_LE(range, 60.0);
      EXPECT_GE(meta.at("box").at("visible_pixels").get<int>(), 12);
    }
  }
  EXPECT_EQ(images, 6u);
}

TEST(DatasetSynth, HorizonTargetsFlyAtTheCamerasHeight) {
  // synth.horizon_fraction 1: every target is seen within +-horizon_elevation_max_deg of the horizontal.
  wingman::testing::TempDir dir;
  DatasetSynthRequest request;
  request.out_dir = dir.file("set");
  request.count = 5;
  request.seed = 4;
  request.config = write_config(dir,
                                "  horizon_fraction: 1.0\n  horizon_elevation_max_deg: 2.0\n"
                                "  camera_height_min_m: 3.0\n  camera_height_max_m: 10.0\n  range_max_m: 30.0\n");
  std::ostringstream progress;
  const DatasetSynthSummary summary = run_dataset_synth(request, progress);
  ASSERT_EQ(summary.images, 5);
  int checked = 0;
  for (const char* split : {"train", "val"}) {
    const fs::path meta_dir = fs::path(request.out_dir) / "meta" / split;
    if (!fs::is_directory(meta_dir)) continue;
    for (const auto& entry : fs::directory_iterator(meta_dir)) {
      const nlohmann::json meta = read_meta(entry.path());
      const Eigen::Vector3d p_cam_in_world = pose(meta.at("T_cam_to_world")).translation();
      const Eigen::Vector3d p_target_in_world = pose(meta.at("target").at("T_body_to_world")).translation();
      const Eigen::Vector3d d = p_target_in_world - p_cam_in_world;
      const double elevation_deg = std::atan2(d.z(), d.head<2>().norm()) * 180.0 / M_PI;
      EXPECT_LE(std::abs(elevation_deg), 2.0 + 1e-6) << entry.path();
      ++checked;
    }
  }
  EXPECT_EQ(checked, 5);

  // Out of range: named with its rule.
  DatasetSynthConfig config;
  config.horizon_fraction = 1.5;
  config.horizon_elevation_max_deg = -1.0;
  const std::vector<std::string> problems = config.validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("synth.horizon_fraction"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("synth.horizon_elevation_max_deg"), std::string::npos) << problems[1];
}

/// Every image of a dataset: split/stem -> (labels, metadata).
std::map<std::string, std::pair<std::vector<training::LabeledBox>, nlohmann::json>> read_images(
    const std::string& dir) {
  std::map<std::string, std::pair<std::vector<training::LabeledBox>, nlohmann::json>> out;
  for (const char* split : {"train", "val"}) {
    if (!fs::is_directory(fs::path(dir) / "images" / split) || fs::is_empty(fs::path(dir) / "images" / split)) continue;
    for (const training::DatasetImage& image : training::load_yolo_dataset(dir + "/data.yaml", split).images) {
      const std::string stem = fs::path(image.image_path).stem().string();
      out[std::string(split) + "/" + stem] = {image.boxes, read_meta(dir + "/meta/" + split + "/" + stem + ".json")};
    }
  }
  return out;
}

TEST(DatasetSynth, DistractorsAreLabelledAsTheirClassesOrLeftAsNegatives) {
  wingman::testing::TempDir dir;
  const std::string keys =
      "  distractors_max: 3\n  negative_fraction: 0.4\n  distractor_px_min: 8\n  distractor_px_max: 40\n";
  std::ostringstream progress;
  const auto run = [&](const std::string& name, const std::string& extra) {
    DatasetSynthRequest request;
    request.out_dir = dir.file(name);
    request.count = 10;
    request.seed = 5;
    request.config = write_config(dir, extra);
    return run_dataset_synth(request, progress);
  };
  const DatasetSynthSummary with_classes = run("classes", keys + "  distractor_classes: true\n");
  EXPECT_EQ(with_classes.images, 10);
  EXPECT_GT(with_classes.negatives, 0);
  EXPECT_LT(with_classes.negatives, 10);
  EXPECT_GT(with_classes.distractors_labelled, 0);
  EXPECT_LE(with_classes.distractors_labelled, with_classes.distractors);
  EXPECT_NE(with_classes.one_line().find("images without a drone"), std::string::npos) << with_classes.one_line();
  EXPECT_EQ(training::load_yolo_dataset(dir.file("classes") + "/data.yaml", "train").class_names,
            (std::vector<std::string>{"drone", "airplane", "bird", "helicopter"}));

  // Each image: its drone's label unless it is a negative, then one label per distractor seen well enough, which is
  // the truth box of the distractor its metadata describes (rebuilt from the spec written there).
  const auto classes = read_images(dir.file("classes"));
  ASSERT_EQ(classes.size(), 10u);
  int negatives = 0, labelled = 0, unlabelled = 0;
  for (const auto& [image, entry] : classes) {
    const auto& [labels, meta] = entry;
    const bool negative = !meta.contains("target");
    negatives += negative;
    const int drones = static_cast<int>(
        std::count_if(labels.begin(), labels.end(), [](const training::LabeledBox& b) { return b.cls == 0; }));
    EXPECT_EQ(drones, negative ? 0 : 1) << image;
    const geometry::CameraModel camera = camera_of(meta, 320, 240);
    size_t expected_labels = negative ? 0 : 1;
    bool any_seen = false;
    for (const nlohmann::json& d : meta.at("distractors")) {
      sim::DistractorSpec spec;
      spec.kind = static_cast<sim::DistractorKind>(d.at("class_id").get<int>());
      EXPECT_EQ(d.at("kind").get<std::string>(), sim::distractor_name(spec.kind));
      const nlohmann::json& js = d.at("spec");
      spec.span_m = js.at("span_m").get<double>();
      spec.length_ratio = js.at("length_ratio").get<double>();
      spec.wing_angle_deg = js.at("wing_angle_deg").get<double>();
      spec.colour = js.at("colour").get<std::vector<double>>();
      spec.accent_colour = js.at("accent_colour").get<std::vector<double>>();
      const sim::DroneModel model = sim::distractor_model(spec);
      EXPECT_NEAR(model.bounding_radius(), d.at("bounding_radius_m").get<double>(), 1e-6);
      const sim::RenderedBox truth = sim::TruthBoxProjector(camera).project(
          model, pose(meta.at("T_cam_to_world")), pose(d.at("T_body_to_world")), d.at("prop_angle_rad").get<double>());
      const nlohmann::json& box = d.at("box");
      const bool seen = box.at("visible").get<bool>() && box.at("visible_pixels").get<int>() >= 12;
      any_seen = any_seen || seen;
      EXPECT_EQ(d.at("labelled").get<bool>(), seen) << image;
      if (!seen) {
        ++unlabelled;
        continue;
      }
      ++labelled;
      ++expected_labels;
      ASSERT_TRUE(truth.visible) << image;
      const int cls = static_cast<int>(spec.kind);
      const bool found = std::any_of(labels.begin(), labels.end(), [&](const training::LabeledBox& b) {
        return b.cls == cls && std::abs(b.cx * 320.0 - truth.cx) < 1e-3 && std::abs(b.cy * 240.0 - truth.cy) < 1e-3 &&
               std::abs(b.w * 320.0 - truth.w) < 1e-3 && std::abs(b.h * 240.0 - truth.h) < 1e-3;
      });
      EXPECT_TRUE(found) << image << ": no class " << cls << " label at the distractor's truth box";
    }
    EXPECT_EQ(labels.size(), expected_labels) << image;
    if (negative) {
      EXPECT_TRUE(any_seen) << image << ": a negative shows a distractor";
    }
  }
  EXPECT_EQ(negatives, with_classes.negatives);
  EXPECT_EQ(labelled, with_classes.distractors_labelled);
  EXPECT_EQ(labelled + unlabelled, with_classes.distractors);

  // `wingman model box-relation` passes over the negatives (nothing to measure) and counts them.
  BoxRelationRequest relation;
  relation.data = dir.file("classes");
  relation.check = "sphere";
  const BoxRelationSummary measured = run_box_relation(relation, progress);
  int val_images = 0, val_negatives = 0;
  for (const auto& [image, entry] : classes) {
    if (image.rfind("val/", 0) != 0) continue;
    ++val_images;
    val_negatives += !entry.second.contains("target");
  }
  EXPECT_EQ(measured.images, val_images);
  EXPECT_EQ(measured.no_target, val_negatives);
  if (val_negatives > 0) {
    EXPECT_NE(measured.markdown().find("without a drone"), std::string::npos) << measured.markdown();
  }

  // Without classes: the same images (the labelling draws nothing), one class, the distractors unlabelled.
  const DatasetSynthSummary one_class = run("one_class", keys);
  EXPECT_EQ(one_class.distractors, with_classes.distractors);
  EXPECT_EQ(one_class.distractors_labelled, 0);
  const auto plain = read_images(dir.file("one_class"));
  ASSERT_EQ(plain.size(), classes.size());
  for (const auto& [image, entry] : plain) {
    const auto& [labels, meta] = entry;
    EXPECT_EQ(labels.size(), meta.contains("target") ? 1u : 0u) << image;
    nlohmann::json expected = classes.at(image).second;  // the same metadata, nothing labelled
    for (nlohmann::json& d : expected.at("distractors")) d["labelled"] = false;
    EXPECT_EQ(meta.dump(), expected.dump()) << image;
  }
}

TEST(DatasetSynth, DistractorsLeaveEachImagesDroneCameraAndSceneAlone) {
  // Their own random stream: with distractors (no negatives) every image keeps the drone, camera and scene of the run
  // without them, except where a distractor hid the drone and the placement was drawn again. (The drone's box may
  // lose visible pixels behind a distractor: "box" is left out of the comparison.)
  wingman::testing::TempDir dir;
  std::ostringstream progress;
  const auto run = [&](const std::string& name, const std::string& extra) {
    DatasetSynthRequest request;
    request.out_dir = dir.file(name);
    request.count = 8;
    request.seed = 9;
    request.config = write_config(dir, extra);
    return run_dataset_synth(request, progress);
  };
  const DatasetSynthSummary none = run("none", "");
  const DatasetSynthSummary some = run("some", "  distractors_max: 4\n  distractor_px_min: 20\n");
  EXPECT_GT(some.distractors, 0);
  const auto a = read_images(dir.file("none")), b = read_images(dir.file("some"));
  ASSERT_EQ(a.size(), b.size());
  int differing = 0;
  for (const auto& [image, entry] : a) {
    nlohmann::json meta_b = b.at(image).second;
    EXPECT_TRUE(meta_b.contains("distractors")) << image;
    EXPECT_FALSE(entry.second.contains("distractors")) << image << ": none asked for";
    nlohmann::json meta_a = entry.second;
    meta_b.erase("distractors");
    meta_b.erase("box");
    meta_a.erase("box");
    if (meta_b.dump() != meta_a.dump()) ++differing;
  }
  EXPECT_LE(differing, some.redrawn - none.redrawn);
}

TEST(DatasetSynth, SameSeedSameBytesOtherSeedOtherImages) {
  wingman::testing::TempDir dir;
  const std::string config = write_config(dir, "  image_format: jpg\n");
  std::ostringstream progress;
  const auto run = [&](const std::string& name, uint64_t seed) {
    DatasetSynthRequest request;
    request.out_dir = dir.file(name);
    request.count = 4;
    request.seed = seed;
    request.config = config;
    run_dataset_synth(request, progress);
    return all_files(request.out_dir);
  };
  const auto a = run("a", 11), b = run("b", 11), c = run("c", 12);
  ASSERT_EQ(a.size(), 4u * 3u + 1u);  // image, label, metadata per image; data.yaml
  EXPECT_TRUE(a == b) << "the same seed must give the same files";
  size_t differing = 0;
  for (const auto& [path, bytes] : a) differing += c.count(path) == 0 || c.at(path) != bytes;
  EXPECT_GE(differing, 4u) << "another seed must give other images";
}

TEST(DatasetSynth, ErrorsNameTheKeyOrTheFolder) {
  wingman::testing::TempDir dir;
  DatasetSynthRequest request;
  request.out_dir = dir.file("set");
  request.count = 1;
  request.config = write_config(dir, "  range_min_m: 80\n  colour: red\n");
  std::ostringstream progress;
  try {
    run_dataset_synth(request, progress);
    FAIL() << "bad config accepted";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("synth.colour"), std::string::npos) << what;
    EXPECT_NE(what.find("synth.range_max_m"), std::string::npos) << what;
  }
  request.config = write_config(dir);
  request.meshes = {dir.file("no_meshes_here")};
  EXPECT_THROW(run_dataset_synth(request, progress), std::runtime_error);
  request.meshes.clear();
  fs::create_directories(request.out_dir + "/images/train");
  std::ofstream(request.out_dir + "/images/train/x.png") << "x";
  try {
    run_dataset_synth(request, progress);
    FAIL() << "an existing dataset was written into";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("already holds a dataset"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(DatasetSynthConfig{}.validate().empty());

  DatasetSynthConfig config;
  config.distractors_max = 17;
  config.distractor_px_min = 50.0;
  config.distractor_px_max = 10.0;
  EXPECT_EQ(config.validate().size(), 2u);
  config.distractors_max = 0;
  config.distractor_px_max = 80.0;
  config.negative_fraction = 0.5;
  const std::vector<std::string> problems = config.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("synth.negative_fraction"), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find("synth.distractors_max"), std::string::npos) << problems[0];
}

TEST(DatasetSynth, CommandLineWritesTheDatasetAndProgressOnlyForALongJob) {
  wingman::testing::TempDir dir;
  const std::string wingman = WINGMAN_EXE;
  const auto ok = wingman::testing::run({wingman, "dataset", "synth", "--out", dir.file("set"), "--count", "2",
                                         "--seed", "4", "--config", write_config(dir)},
                                        std::chrono::seconds(120));
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("wrote 2 images"), std::string::npos) << ok.out;
  // common::Progress on stderr: nothing for a job under 5 s, else its closing line (the text: test_progress.cpp).
  EXPECT_TRUE(ok.err.find("images/s") == std::string::npos ||
              ok.err.find("wingman dataset synth: 2/2 images (100.0 %)") != std::string::npos)
      << ok.err;
  EXPECT_TRUE(fs::exists(dir.file("set/data.yaml")));
  // A bad key: exit 2 and one line naming it.
  std::ofstream(dir.file("bad.yaml")) << "synth:\n  widht: 640\n";
  const auto bad = wingman::testing::run(
      {wingman, "dataset", "synth", "--out", dir.file("other"), "--count", "1", "--config", dir.file("bad.yaml")});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("synth.widht"), std::string::npos) << bad.err;
  const auto printed =
      wingman::testing::run({wingman, "dataset", "synth", "--out", "x", "--count", "1", "--print-config"});
  EXPECT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_NE(printed.out.find("render:"), std::string::npos) << printed.out;
  EXPECT_NE(printed.out.find("synth:"), std::string::npos) << printed.out;
  const auto no_count = wingman::testing::run({wingman, "dataset", "synth", "--out", dir.file("third")});
  EXPECT_EQ(no_count.exit_code, 2);
  EXPECT_NE(no_count.err.find("--count"), std::string::npos) << no_count.err;
}

}  // namespace
}  // namespace wingman::tools
