// SPDX-License-Identifier: MIT
// `wingman dataset from-log`: images paired with their ground truth by seq in either order, labels that are the
// visible boxes of the image's camera clipped to the image, --every, negatives, counted drops, and errors that name
// the log or file. Real LCM log files (lcm::LogFile), read back with the trainer's dataset reader.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/tools/dataset_from_log.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;
constexpr int kW = 64, kH = 48;

/// A BGR8 frame whose pixels encode its seq (so the written image can be traced back).
wingman::image_t frame(int64_t seq, int32_t camera_id = 0) {
  wingman::image_t m{};
  m.utime = 1000000 + seq * 33333;
  m.seq = seq;
  m.camera_id = camera_id;
  m.width = kW;
  m.height = kH;
  m.stride = 3 * kW;
  m.pixel_format = wingman::image_t::BGR8;
  m.size = m.stride * kH;
  m.data.assign(static_cast<size_t>(m.size), static_cast<uint8_t>(10 + seq));
  return m;
}

wingman::truth_box_t box(float cx, float cy, float w, float h, bool visible = true, int32_t camera_id = 0) {
  wingman::truth_box_t b{};
  b.vehicle_id = 1;
  b.camera_id = camera_id;
  b.cx = cx;
  b.cy = cy;
  b.w = w;
  b.h = h;
  b.visible = visible;
  b.range = 5.0;
  return b;
}

wingman::ground_truth_t truth(int64_t image_seq, std::vector<wingman::truth_box_t> boxes) {
  wingman::ground_truth_t t{};
  t.utime = 1000000 + image_seq * 33333;
  t.frame = 0;
  t.image_seq = image_seq;
  t.num_vehicles = 0;
  t.boxes = std::move(boxes);
  t.num_boxes = static_cast<int32_t>(t.boxes.size());
  return t;
}

class LogWriter {
 public:
  explicit LogWriter(const std::string& path) : log_(path, "w") { EXPECT_TRUE(log_.good()) << path; }
  template <class Msg>
  void write(const std::string& channel, const Msg& m) {
    std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
    ASSERT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
    raw(channel, buf);
  }
  void raw(const std::string& channel, std::vector<uint8_t> bytes) {
    lcm::LogEvent ev{};
    ev.eventnum = n_++;
    ev.timestamp = 1000000 + n_;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(bytes.size());
    ev.data = bytes.data();
    ASSERT_EQ(log_.writeEvent(&ev), 0);
  }

 private:
  lcm::LogFile log_;
  int64_t n_ = 0;
};

/// A flight of 6 frames: 0 and 1 with truth after the image, 2 with truth before, 3 with its drone invisible and a
/// box of another camera (a negative), 4 with a box half outside the image, one below min_box_px and one not finite,
/// 5 with no ground truth at all; garbage on both channels.
std::string write_flight(const wingman::testing::TempDir& dir, const std::string& name = "flight.lcmlog") {
  const std::string path = dir.file(name);
  LogWriter log(path);
  log.write("IMAGE_CAM0", frame(0));
  log.write("GROUND_TRUTH", truth(0, {box(32, 24, 10, 6)}));
  log.write("IMAGE_CAM0", frame(1));
  log.write("GROUND_TRUTH", truth(1, {box(20, 10, 8, 4), box(50, 30, 6, 6)}));
  log.write("GROUND_TRUTH", truth(2, {box(16, 16, 12, 12)}));
  log.write("IMAGE_CAM0", frame(2));
  log.raw("IMAGE_CAM0", {1, 2, 3});       // not an image_t
  log.raw("GROUND_TRUTH", {9, 9, 9, 9});  // not a ground_truth_t
  log.write("OTHER", frame(99));          // other channels are ignored
  log.write("IMAGE_CAM0", frame(3));
  log.write("GROUND_TRUTH", truth(3, {box(32, 24, 10, 6, false), box(32, 24, 10, 6, true, 7)}));
  log.write("IMAGE_CAM0", frame(4));
  log.write("GROUND_TRUTH", truth(4, {box(60, 10, 20, 8), box(10, 40, 1.5f, 8), box(NAN, 10, 5, 5)}));
  log.write("IMAGE_CAM0", frame(5));
  return path;
}

DatasetFromLogRequest request(const wingman::testing::TempDir& dir, const std::string& log) {
  DatasetFromLogRequest r;
  r.logs = {log};
  r.out_dir = dir.file("ds");
  r.image_format = "png";
  return r;
}

TEST(DatasetFromLog, PairsEveryImageWithItsTruthAndWritesClippedVisibleBoxes) {
  wingman::testing::TempDir dir;
  std::ostringstream progress;
  const DatasetFromLogSummary s = run_dataset_from_log(request(dir, write_flight(dir)), progress);
  EXPECT_EQ(s.images, 5);
  EXPECT_EQ(s.boxes, 5);      // 1 + 2 + 1 + 0 + 1
  EXPECT_EQ(s.negatives, 1);  // frame 3
  EXPECT_EQ(s.unmatched, 1);  // frame 5
  EXPECT_EQ(s.undecodable, 2);
  EXPECT_EQ(s.skipped, 0);
  EXPECT_NE(progress.str().find("5 of 6 images written"), std::string::npos) << progress.str();

  const training::YoloDataset ds = training::load_yolo_dataset(dir.file("ds/data.yaml"), "train");
  ASSERT_EQ(ds.images.size(), 5u);
  EXPECT_EQ(fs::path(ds.images[0].image_path).filename(), "flight_0000000.png");
  ASSERT_EQ(ds.images[0].boxes.size(), 1u);
  EXPECT_NEAR(ds.images[0].boxes[0].cx, 32.0 / kW, 1e-5);
  EXPECT_NEAR(ds.images[0].boxes[0].cy, 24.0 / kH, 1e-5);
  EXPECT_NEAR(ds.images[0].boxes[0].w, 10.0 / kW, 1e-5);
  EXPECT_NEAR(ds.images[0].boxes[0].h, 6.0 / kH, 1e-5);
  EXPECT_EQ(ds.images[1].boxes.size(), 2u);
  ASSERT_EQ(ds.images[2].boxes.size(), 1u);  // truth before its image
  EXPECT_NEAR(ds.images[2].boxes[0].w, 12.0 / kW, 1e-5);
  EXPECT_TRUE(ds.images[3].has_label_file);  // a negative: an empty label file
  EXPECT_TRUE(ds.images[3].boxes.empty());
  // Frame 4: x 50..70 clipped to 50..64; the 1.5-px wide box and the NaN one are dropped.
  ASSERT_EQ(ds.images[4].boxes.size(), 1u);
  EXPECT_NEAR(ds.images[4].boxes[0].cx, 57.0 / kW, 1e-5);
  EXPECT_NEAR(ds.images[4].boxes[0].w, 14.0 / kW, 1e-5);
  EXPECT_NEAR(ds.images[4].boxes[0].h, 8.0 / kH, 1e-5);
  // The pixels are the frame's own (lossless png).
  const cv::Mat img = cv::imread(ds.images[2].image_path, cv::IMREAD_COLOR);
  ASSERT_EQ(img.size(), cv::Size(kW, kH));
  EXPECT_EQ(img.at<cv::Vec3b>(5, 5), cv::Vec3b(12, 12, 12));
}

TEST(DatasetFromLog, EveryNthImageSkipNegativesAndTheValSplit) {
  wingman::testing::TempDir dir;
  DatasetFromLogRequest r = request(dir, write_flight(dir));
  r.every = 2;  // images 0, 2, 4
  r.split = "val";
  r.keep_negatives = false;
  std::ostringstream progress;
  const DatasetFromLogSummary s = run_dataset_from_log(r, progress);
  EXPECT_EQ(s.images, 3);
  EXPECT_EQ(s.skipped, 3);  // 1, 3, 5 by --every
  const training::YoloDataset ds = training::load_yolo_dataset(dir.file("ds/data.yaml"), "val");
  ASSERT_EQ(ds.images.size(), 3u);
  EXPECT_EQ(fs::path(ds.images[1].image_path).filename(), "flight_0000002.png");

  // Without --every, frame 3 (no drone) is left out as a negative.
  wingman::testing::TempDir dir2;
  DatasetFromLogRequest r2 = request(dir2, write_flight(dir2));
  r2.keep_negatives = false;
  const DatasetFromLogSummary s2 = run_dataset_from_log(r2, progress);
  EXPECT_EQ(s2.images, 4);
  EXPECT_EQ(s2.negatives, 0);
  EXPECT_EQ(s2.skipped, 1);
}

TEST(DatasetFromLog, MoreLogsExtendTheDatasetButNeverOverwrite) {
  wingman::testing::TempDir dir;
  std::ostringstream progress;
  run_dataset_from_log(request(dir, write_flight(dir, "a.lcmlog")), progress);
  run_dataset_from_log(request(dir, write_flight(dir, "b.lcmlog")), progress);
  EXPECT_EQ(training::load_yolo_dataset(dir.file("ds/data.yaml"), "train").images.size(), 10u);
  try {
    run_dataset_from_log(request(dir, dir.file("a.lcmlog")), progress);
    FAIL() << "a second run over the same log must not overwrite its images";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a_0000000.png: already exists"), std::string::npos) << e.what();
  }
}

TEST(DatasetFromLog, ErrorsNameTheLogAndWhatWasExpected) {
  wingman::testing::TempDir dir;
  std::ostringstream progress;
  // Images but no ground truth.
  const std::string no_truth = dir.file("no_truth.lcmlog");
  {
    LogWriter log(no_truth);
    log.write("IMAGE_CAM0", frame(0));
  }
  try {
    run_dataset_from_log(request(dir, no_truth), progress);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(no_truth + ": 1 images on IMAGE_CAM0 but no ground_truth_t on GROUND_TRUTH"),
              std::string::npos)
        << e.what();
  }
  // No images.
  const std::string no_images = dir.file("no_images.lcmlog");
  {
    LogWriter log(no_images);
    log.write("GROUND_TRUTH", truth(0, {box(32, 24, 10, 6)}));
  }
  try {
    run_dataset_from_log(request(dir, no_images), progress);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(no_images + ": no image_t on IMAGE_CAM0"), std::string::npos) << e.what();
  }
  // A missing log.
  try {
    run_dataset_from_log(request(dir, dir.file("missing.lcmlog")), progress);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.lcmlog: cannot open LCM log"), std::string::npos) << e.what();
  }
  // Bad requests name the option.
  DatasetFromLogRequest r = request(dir, no_truth);
  r.split = "test";
  EXPECT_THROW(run_dataset_from_log(r, progress), std::invalid_argument);
  r = request(dir, no_truth);
  r.every = 0;
  try {
    run_dataset_from_log(r, progress);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "--every 0: must be >= 1");
  }
  r = request(dir, no_truth);
  r.image_format = "gif";
  EXPECT_THROW(run_dataset_from_log(r, progress), std::invalid_argument);
}

TEST(DatasetFromLog, CommandLineWritesTheDatasetAndExitsTwoOnABadArgumentOneOnABadLog) {
  wingman::testing::TempDir dir;
  const std::string wingman = WINGMAN_EXE;
  const std::string log = write_flight(dir);
  const auto ok = wingman::testing::run(
      {wingman, "dataset", "from-log", log, "--out", dir.file("ds"), "--every", "2", "--format", "png"});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.out.find("wrote 3 images (3 boxes, 0 negatives)"), std::string::npos) << ok.out;
  EXPECT_TRUE(fs::exists(dir.file("ds/images/train/flight_0000004.png")));
  const auto bad_split =
      wingman::testing::run({wingman, "dataset", "from-log", log, "--out", dir.file("ds2"), "--split", "test"});
  EXPECT_EQ(bad_split.exit_code, 2);
  EXPECT_NE(bad_split.err.find("wingman dataset from-log: error: --split 'test': expected train or val"),
            std::string::npos)
      << bad_split.err;
  const auto missing =
      wingman::testing::run({wingman, "dataset", "from-log", dir.file("none.lcmlog"), "--out", dir.file("ds3")});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.lcmlog: cannot open LCM log for reading"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace wingman::tools
