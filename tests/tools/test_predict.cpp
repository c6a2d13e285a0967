// SPDX-License-Identifier: MIT
// `wingman predict`'s label lines: the box's class in the first field, six fields that training's reader parses back.
#include <wingman/tools/predict.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace wingman::tools {
namespace {

detector::Box box(float cx, float cy, float w, float h, float confidence, int class_id, float drone_score) {
  detector::Box b;
  b.cx = cx;
  b.cy = cy;
  b.w = w;
  b.h = h;
  b.confidence = confidence;
  b.class_id = class_id;
  b.drone_score = drone_score;
  return b;
}

std::vector<std::string> fields(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string f; in >> f;) out.push_back(f);
  return out;
}

TEST(PredictionLine, WritesTheBoxClassFirstAndItsConfidenceLastInSixFields) {
  // A bird (class 2) of a multi-class model in a 200 x 100 image.
  const std::string bird = prediction_line(box(50, 25, 20, 10, 0.75f, 2, 0.05f), 200, 100);
  EXPECT_EQ(bird, "2 0.250000 0.250000 0.100000 0.100000 0.750000\n");
  EXPECT_EQ(fields(bird).size(), 6u);
  // A drone of the shipped single-class model: the line it always wrote.
  EXPECT_EQ(prediction_line(box(100, 50, 40, 20, 0.9f, 0, 0.9f), 200, 100),
            "0 0.500000 0.500000 0.200000 0.200000 0.900000\n");
  EXPECT_EQ(prediction_line(box(100, 50, 40, 20, 0.6f, 3, 0.2f), 200, 100).substr(0, 2), "3 ");  // helicopter
}

TEST(PredictionLine, TrainingsPredictionReaderParsesEveryClassBack) {
  testing::TempDir dir;
  const std::string path = dir.file("image.txt");
  {
    std::ofstream f(path);
    for (int class_id = 0; class_id < 4; ++class_id)
      f << prediction_line(box(40.0f + 30.0f * class_id, 50, 20, 10, 0.5f + 0.1f * class_id, class_id, 0.1f), 200, 100);
  }
  const std::vector<training::PredictedBox> read = training::read_yolo_predictions(path, 4);
  ASSERT_EQ(read.size(), 4u);
  for (int class_id = 0; class_id < 4; ++class_id) {
    const training::PredictedBox& p = read[static_cast<size_t>(class_id)];
    EXPECT_EQ(p.box.cls, class_id);
    EXPECT_NEAR(p.box.cx, (40.0 + 30.0 * class_id) / 200.0, 1e-6);
    EXPECT_NEAR(p.confidence, 0.5 + 0.1 * class_id, 1e-6);
  }
}

TEST(Predict, AFolderOfMixedSizesGivesTheBoxesOfOneImageAtATime) {
  // Issue #34: the pipeline keeps the backend factory and calls it again for an image of another aspect; the factory
  // read a dangling `batch` then (garbage max_batch: most images failed or fell back to the CPU). Three images of
  // three aspects (a dark square "drone" on sky), zoom-in on (batch 8), OpenCL backend: the folder run writes the same
  // label files as three runs of one image each. Under ASan the dangling read is reported.
  testing::TempDir dir;
  const std::filesystem::path folder = dir.file("images");
  std::filesystem::create_directories(folder);
  const std::vector<cv::Size> sizes = {{640, 512}, {1280, 720}, {512, 512}};
  std::vector<std::string> names;
  for (size_t i = 0; i < sizes.size(); ++i) {
    cv::Mat img(sizes[i], CV_8UC3, cv::Scalar(200, 170, 140));
    cv::rectangle(img, cv::Rect(sizes[i].width / 3, sizes[i].height / 3, 40, 24), cv::Scalar(30, 30, 30), cv::FILLED);
    names.push_back("img" + std::to_string(i));
    cv::imwrite((folder / (names.back() + ".png")).string(), img);
  }
  auto options = [&](const std::vector<std::string>& inputs, const std::string& out_dir) {
    PredictOptions o;
    o.inputs = inputs;
    o.out_dir = out_dir;
    o.backend = "opencl";  // the real PoCL backend: its buffers are sized by the batch
    o.detection.zoom_in = true;
    o.detection.p_thresh = 0.01f;  // boxes on these synthetic images, so there is something to compare
    return o;
  };
  std::ostringstream out, err;
  ASSERT_EQ(run_predict(options({folder.string()}, dir.file("together")), out, err), 0) << err.str();
  for (const auto& name : names) {
    std::ostringstream out1, err1;
    ASSERT_EQ(run_predict(options({(folder / (name + ".png")).string()}, dir.file("alone_" + name)), out1, err1), 0)
        << err1.str();
    std::ifstream together(dir.file("together/" + name + ".txt")),
        alone(dir.file("alone_" + name + "/" + name + ".txt"));
    ASSERT_TRUE(together.good()) << name;
    ASSERT_TRUE(alone.good()) << name;
    const std::string a((std::istreambuf_iterator<char>(together)), std::istreambuf_iterator<char>());
    const std::string b((std::istreambuf_iterator<char>(alone)), std::istreambuf_iterator<char>());
    EXPECT_EQ(a, b) << name;
  }
  EXPECT_EQ(err.str().find("max_batch"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace wingman::tools
