// SPDX-License-Identifier: MIT
// YOLO-layout datasets: label parsing with errors that name file, line and field; folder and data.yaml layouts.
#include <wingman/training/yolo_dataset.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <functional>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "(no DatasetError)";
}

void write(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path) << text;
}

void write_image(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  ASSERT_TRUE(cv::imwrite(path, cv::Mat(8, 10, CV_8UC3, cv::Scalar(200, 180, 160))));
}

TEST(YoloLabels, ParsesBoxesAndBlankLines) {
  const auto boxes = parse_yolo_labels("0 0.5 0.25 0.1 0.2\n\n1 1 0 1 0.05\n", 2, "a.txt");
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].cls, 0);
  EXPECT_FLOAT_EQ(boxes[0].cx, 0.5f);
  EXPECT_FLOAT_EQ(boxes[0].cy, 0.25f);
  EXPECT_FLOAT_EQ(boxes[0].w, 0.1f);
  EXPECT_FLOAT_EQ(boxes[0].h, 0.2f);
  EXPECT_EQ(boxes[1].cls, 1);
  EXPECT_TRUE(parse_yolo_labels("", 1, "empty.txt").empty());
}

TEST(YoloLabels, ErrorsNameFileLineAndField) {
  const std::string ok = "0 0.5 0.5 0.1 0.1\n";
  EXPECT_NE(error_of([&] {
              parse_yolo_labels(ok + "0 0.5 0.5 0.1\n", 1, "l.txt");
            }).find("l.txt:2: expected 5 fields 'class cx cy w h', got 4"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse_yolo_labels("x 0.5 0.5 0.1 0.1\n", 1, "l.txt");
            }).find("l.txt:1: field class = 'x': expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse_yolo_labels(ok + ok + "1 0.5 0.5 0.1 0.1\n", 1, "l.txt");
            }).find("l.txt:3: field class = 1: expected 0..0 (1 classes)"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse_yolo_labels("0 1.5 0.5 0.1 0.1\n", 1, "l.txt");
            }).find("l.txt:1: field cx = 1.5: expected 0..1"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse_yolo_labels("0 0.5 0.5 0 0.1\n", 1, "l.txt"); }).find("l.txt:1: field w = 0"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse_yolo_labels("0 0.5 0.5 0.1 abc\n", 1, "l.txt");
            }).find("l.txt:1: field h = 'abc': expected a number"),
            std::string::npos);
}

TEST(YoloLabels, PredictionsNeedAConfidence) {
  testing::TempDir dir;
  write(dir.file("p.txt"), "0 0.5 0.5 0.1 0.1 0.75\n");
  const auto p = read_yolo_predictions(dir.file("p.txt"), 1);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_FLOAT_EQ(p[0].confidence, 0.75f);
  write(dir.file("q.txt"), "0 0.5 0.5 0.1 0.1\n");
  EXPECT_NE(error_of([&] { read_yolo_predictions(dir.file("q.txt"), 1); }).find("q.txt:1: expected 6 fields"),
            std::string::npos);
  write(dir.file("r.txt"), "0 0.5 0.5 0.1 0.1 1.5\n");
  EXPECT_NE(error_of([&] { read_yolo_predictions(dir.file("r.txt"), 1); }).find("field confidence = 1.5"),
            std::string::npos);
}

TEST(YoloLabels, LabelPathReplacesTheLastImagesFolder) {
  EXPECT_EQ(label_path_for("d/images/train/a.jpg"), "d/labels/train/a.txt");
  EXPECT_EQ(label_path_for("/x/images/y/images/v/b.png"), "/x/images/y/labels/v/b.txt");
  EXPECT_EQ(label_path_for("images/c.jpeg"), "labels/c.txt");
  EXPECT_NE(error_of([] { label_path_for("d/pictures/a.jpg"); }).find("not under an 'images' folder"),
            std::string::npos);
}

TEST(YoloDataset, EvenlySpacedSubsetsSampleTheWholeSplit) {
  EXPECT_EQ(evenly_spaced(10, 3), (std::vector<size_t>{0, 3, 6}));
  EXPECT_EQ(evenly_spaced(4, 0), (std::vector<size_t>{0, 1, 2, 3}));
  EXPECT_EQ(evenly_spaced(3, 5), (std::vector<size_t>{0, 1, 2}));
  EXPECT_TRUE(evenly_spaced(0, 2).empty());
}

TEST(YoloDatasetLoad, FolderWithSplitsAndNegatives) {
  testing::TempDir dir;
  write_image(dir.file("images/train/b.jpg"));
  write_image(dir.file("images/train/a.png"));
  write_image(dir.file("images/val/c.jpg"));
  write(dir.file("labels/train/a.txt"), "0 0.5 0.5 0.2 0.2\n0 0.1 0.1 0.1 0.1\n");
  write(dir.file("labels/train/b.txt"), "");  // an empty file: a negative
  const YoloDataset train = load_yolo_dataset(dir.path(), "train");
  ASSERT_EQ(train.images.size(), 2u);
  EXPECT_EQ(fs::path(train.images[0].image_path).filename(), "a.png");  // sorted
  EXPECT_EQ(train.images[0].boxes.size(), 2u);
  EXPECT_TRUE(train.images[1].has_label_file);
  EXPECT_EQ(train.box_count(), 2u);
  EXPECT_EQ(train.negative_count(), 1u);
  EXPECT_EQ(train.class_names, std::vector<std::string>{"drone"});
  const YoloDataset val = load_yolo_dataset(dir.path(), "val");
  ASSERT_EQ(val.images.size(), 1u);
  EXPECT_FALSE(val.images[0].has_label_file);  // no label file: a negative
  EXPECT_NE(error_of([&] { load_yolo_dataset(dir.path(), "test"); }).find("no images folder for split 'test'"),
            std::string::npos);
}

TEST(YoloDatasetLoad, DataYamlWithNamesMapListFileAndBadLabelNamed) {
  testing::TempDir dir;
  write_image(dir.file("root/images/x/1.jpg"));
  write_image(dir.file("root/images/x/2.jpg"));
  write(dir.file("root/labels/x/1.txt"), "1 0.5 0.5 0.2 0.2\n");
  write(dir.file("root/train.txt"), "images/x/2.jpg\n\nimages/x/1.jpg\n");
  write(dir.file("data.yaml"),
        "path: root\ntrain: train.txt\nval: [images/x]\nnames:\n  0: drone\n  1: bird\ngenerator: anything\n");
  const YoloDataset train = load_yolo_dataset(dir.file("data.yaml"), "train");
  EXPECT_EQ(train.class_names, (std::vector<std::string>{"drone", "bird"}));
  ASSERT_EQ(train.images.size(), 2u);
  EXPECT_EQ(train.images[0].boxes.size(), 1u);
  EXPECT_EQ(train.images[0].boxes[0].cls, 1);
  EXPECT_EQ(load_yolo_dataset(dir.file("data.yaml"), "val").images.size(), 2u);
  EXPECT_NE(error_of([&] { load_yolo_dataset(dir.file("data.yaml"), "test"); }).find("no key 'test'"),
            std::string::npos);
  write(dir.file("root/labels/x/2.txt"), "0 0.5 0.5 0.2 0.2\n2 0.5 0.5 0.2 0.2\n");
  const std::string e = error_of([&] { load_yolo_dataset(dir.file("data.yaml"), "train"); });
  EXPECT_NE(e.find("labels/x/2.txt:2: field class = 2: expected 0..1 (2 classes)"), std::string::npos) << e;
  write(dir.file("bad.yaml"), "train: [a\n");
  EXPECT_NE(error_of([&] { load_yolo_dataset(dir.file("bad.yaml"), "train"); }).find("bad.yaml:"), std::string::npos);
  write(dir.file("missing.yaml"), "train: nowhere\n");
  EXPECT_NE(error_of([&] { load_yolo_dataset(dir.file("missing.yaml"), "train"); }).find("'nowhere'"),
            std::string::npos);
}

TEST(YoloDatasetWrite, LabelsAndDataYamlReadBack) {
  testing::TempDir dir;
  const std::vector<LabeledBox> boxes = {{0, 0.25f, 0.5f, 0.125f, 0.0625f}, {0, 0.75f, 0.5f, 0.5f, 1.0f}};
  write_yolo_labels(dir.file("labels/train/a.txt"), boxes);
  write_image(dir.file("images/train/a.jpg"));
  write_image(dir.file("images/val/b.jpg"));
  write_data_yaml(dir.file("data.yaml"), {"drone"}, {"made by a test"});
  const YoloDataset ds = load_yolo_dataset(dir.file("data.yaml"), "train");
  ASSERT_EQ(ds.images.size(), 1u);
  ASSERT_EQ(ds.images[0].boxes.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_FLOAT_EQ(ds.images[0].boxes[i].cx, boxes[i].cx);
    EXPECT_FLOAT_EQ(ds.images[0].boxes[i].h, boxes[i].h);
  }
  EXPECT_EQ(load_yolo_dataset(dir.file("data.yaml"), "val").images.size(), 1u);
  // Issue #34: `path: .` made Ultralytics look in its datasets folder; without the key the root is the file's folder.
  std::ifstream yaml(dir.file("data.yaml"));
  const std::string text((std::istreambuf_iterator<char>(yaml)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find("path:"), std::string::npos) << text;
}

}  // namespace
}  // namespace wingman::training
