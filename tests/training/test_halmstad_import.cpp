// SPDX-License-Identifier: MIT
// Halmstad import on two real clips (skipped without ../shared/datasets/halmstad): frames, labels, tightening,
// the split by clip, and errors that name the file.
#include <wingman/training/halmstad_import.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

std::string halmstad_root() {
  const char* env = std::getenv("WINGMAN_SOURCE_DIR");
  const fs::path root = fs::path(env ? env : ".") / ".." / "shared" / "datasets" / "halmstad";
  return fs::is_regular_file(root / "clips.csv") ? root.string() : "";
}

#define REQUIRE_HALMSTAD(root)                                                         \
  const std::string root = halmstad_root();                                            \
  if (root.empty())                                                                    \
  GTEST_SKIP() << "../shared/datasets/halmstad is absent (read-only shared data, not " \
                  "part of the repository): the import is not tested here"

TEST(HalmstadImport, DefaultsAreValidOnceFoldersAreGiven) {
  HalmstadImportOptions o;
  o.root = "r";
  o.out_dir = "o";
  EXPECT_TRUE(o.validate().empty());
  o.frame_step = 0;
  o.val_fraction = 2;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("frame_step = 0"), std::string::npos);
  EXPECT_NE(p[1].find("val_fraction = 2"), std::string::npos);
}

TEST(HalmstadImport, TwoClipsSplitByClipWithTightenedDroneBoxes) {
  REQUIRE_HALMSTAD(root);
  testing::TempDir out;
  HalmstadImportOptions o;
  o.root = root;
  o.out_dir = out.path();
  o.clips = {"V_DRONE_001", "V_BIRD_004"};
  o.frame_step = 50;
  o.negative_frame_step = 100;
  o.val_fraction = 0.0;
  std::vector<std::string> log;
  const HalmstadImportSummary s = import_halmstad(o, [&](const std::string& l) { log.push_back(l); });
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(s.train_clips.size(), 2u);
  EXPECT_TRUE(s.val_clips.empty());
  // V_DRONE_001 has about 300 frames: frames 0, 50, ..., 300 at most; the bird clip every 100th.
  EXPECT_GE(s.train_images, 8);
  EXPECT_LE(s.train_images, 11);
  EXPECT_GT(s.boxes, 0);
  EXPECT_GT(s.tightened, 0) << s.report();
  EXPECT_LT(s.mean_area_ratio, 0.9) << "tight boxes should be smaller than the loose ones";
  const YoloDataset ds = load_yolo_dataset(out.file("data.yaml"), "train");
  EXPECT_EQ(static_cast<int64_t>(ds.images.size()), s.train_images);
  size_t drone_images = 0;
  for (const DatasetImage& img : ds.images) {
    const bool is_drone = img.image_path.find("V_DRONE_001_") != std::string::npos;
    EXPECT_EQ(!img.boxes.empty(), is_drone) << img.image_path;  // bird frames are negatives
    drone_images += is_drone ? 1 : 0;
  }
  EXPECT_GE(drone_images, 6u);
  std::ifstream splits(out.file("splits.csv"));
  std::string header;
  std::getline(splits, header);
  EXPECT_EQ(header, "clip,class,distance_bin,split,images");
}

TEST(HalmstadImport, ValSplitNeverSharesAClip) {
  REQUIRE_HALMSTAD(root);
  testing::TempDir out;
  HalmstadImportOptions o;
  o.root = root;
  o.out_dir = out.path();
  o.clips = {"V_AIRPLANE_001", "V_AIRPLANE_004", "V_AIRPLANE_010", "V_AIRPLANE_015"};  // all MEDIUM airplanes
  o.negative_frame_step = 150;
  o.val_fraction = 0.5;
  o.tighten = false;
  const HalmstadImportSummary s = import_halmstad(o);
  EXPECT_EQ(s.train_clips.size(), 2u);
  EXPECT_EQ(s.val_clips.size(), 2u);
  std::set<std::string> clips_in[2];
  const char* splits[2] = {"train", "val"};
  for (int k = 0; k < 2; ++k)
    for (const DatasetImage& img : load_yolo_dataset(out.file("data.yaml"), splits[k]).images) {
      const std::string stem = fs::path(img.image_path).stem().string();
      clips_in[k].insert(stem.substr(0, stem.rfind('_')));
    }
  for (const std::string& c : clips_in[0]) EXPECT_EQ(clips_in[1].count(c), 0u) << c << " is in both splits";
  EXPECT_EQ(clips_in[0].size(), 2u);
  EXPECT_EQ(clips_in[1].size(), 2u);
  // The same seed gives the same split.
  testing::TempDir again;
  o.out_dir = again.path();
  EXPECT_EQ(import_halmstad(o).val_clips, s.val_clips);
}

TEST(HalmstadImport, DistractorClassesLabelTheOtherClipsWithTheSameSplit) {
  REQUIRE_HALMSTAD(root);
  testing::TempDir out, plain;
  HalmstadImportOptions o;
  o.root = root;
  o.out_dir = out.path();
  o.clips = {"V_DRONE_001", "V_BIRD_004", "V_HELICOPTER_002", "V_AIRPLANE_001", "V_AIRPLANE_004"};
  o.frame_step = 100;
  o.negative_frame_step = 100;
  o.val_fraction = 0.5;
  o.distractor_classes = true;
  const HalmstadImportSummary s = import_halmstad(o);
  EXPECT_GT(s.boxes, 0);
  EXPECT_GT(s.distractor_boxes, 0) << s.report();
  // The split is the one the drone-only import makes.
  HalmstadImportOptions drone_only = o;
  drone_only.out_dir = plain.path();
  drone_only.distractor_classes = false;
  const HalmstadImportSummary p = import_halmstad(drone_only);
  EXPECT_EQ(p.val_clips, s.val_clips);
  EXPECT_EQ(p.train_clips, s.train_clips);
  EXPECT_EQ(p.distractor_boxes, 0);
  // Every frame's boxes carry its clip's class: 0 drone, 1 airplane, 2 bird, 3 helicopter.
  const std::map<std::string, int> kClass = {{"DRONE", 0}, {"AIRPLANE", 1}, {"BIRD", 2}, {"HELICOPTER", 3}};
  size_t boxes_seen[4] = {0, 0, 0, 0};
  for (const char* split : {"train", "val"}) {
    const YoloDataset ds = load_yolo_dataset(out.file("data.yaml"), split);
    ASSERT_EQ(ds.class_names, (std::vector<std::string>{"drone", "airplane", "bird", "helicopter"}));
    for (const DatasetImage& img : ds.images) {
      const std::string stem = fs::path(img.image_path).stem().string();
      const std::string cls = stem.substr(2, stem.find('_', 2) - 2);
      for (const LabeledBox& b : img.boxes) {
        EXPECT_EQ(b.cls, kClass.at(cls)) << img.image_path;
        ++boxes_seen[b.cls];
      }
    }
  }
  for (int c = 0; c < 4; ++c) EXPECT_GT(boxes_seen[c], 0u) << "no box of class " << c;
  EXPECT_EQ(static_cast<int64_t>(boxes_seen[1] + boxes_seen[2] + boxes_seen[3]), s.distractor_boxes);
}

TEST(HalmstadImport, DistractorClassesNeedTheNegativesAndKnownClassNames) {
  HalmstadImportOptions o;
  o.root = "r";
  o.out_dir = "o";
  o.distractor_classes = true;
  o.negatives = false;
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("distractor_classes"), std::string::npos) << problems[0];
  // A label whose class is none of the four: one error naming the file, the line and the value.
  testing::TempDir dir;
  fs::create_directories(dir.file("labels"));
  std::ofstream(dir.file("clips.csv")) << "clip,class,drone_type,distance_bin,frames,boxes,note\n"
                                       << "V_BIRD_900,BIRD,,CLOSE,2,2,\n";
  std::ofstream(dir.file("labels/V_BIRD_900.csv")) << "frame,class,x,y,w,h\n0,BIRD,1,1,5,5\n1,KITE,2,2,5,5\n";
  o.root = dir.path();
  o.out_dir = dir.file("out");
  o.negatives = true;
  try {
    import_halmstad(o);
    FAIL() << "no exception";
  } catch (const DatasetError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("V_BIRD_900.csv:3: field class = 'KITE'"), std::string::npos) << what;
  }
}

TEST(HalmstadImport, UnknownClipAndMissingListAreNamed) {
  testing::TempDir dir;
  HalmstadImportOptions o;
  o.root = dir.path();
  o.out_dir = dir.file("out");
  try {
    import_halmstad(o);
    FAIL() << "no exception";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("clips.csv: cannot read the clip list"), std::string::npos) << e.what();
  }
  REQUIRE_HALMSTAD(root);
  o.root = root;
  o.clips = {"V_DRONE_999"};
  try {
    import_halmstad(o);
    FAIL() << "no exception";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("clip 'V_DRONE_999' is not listed"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::training
