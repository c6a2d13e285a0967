// SPDX-License-Identifier: MIT
// wingman-detector as a process, file to file, with random weights written by our own writer:
// one detections_t per good frame carrying the frame's utime and seq; bad frames dropped and counted;
// the same input gives the same detections (but for the measured latency) run after run.
#include "test_support.hpp"
#include "test_video.hpp"

#include <gtest/gtest.h>
#include <wingman/detections_t.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>

#include <chrono>
#include <fstream>
#include <iostream>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::read_log;
using wingman::testing::run;
using wingman::testing::TempDir;

constexpr int kFrames = 6;

/// Random weights for the built-in thesis network (fixed seed).
std::string write_random_weights(const TempDir& dir) {
  auto model = wingman::detector::parse_darknet_cfg_string(wingman::detector::builtin_thesis_cfg(), "thesis");
  wingman::detector::randomize_weights(model, 7);
  const std::string path = dir.file("random.weights");
  wingman::detector::save_darknet_weights(model, path);
  return path;
}

/// kFrames camera frames (the real camera driver, fast mode) plus one impossible and one garbage image.
std::string write_input_log(const TempDir& dir) {
  const std::string video = dir.file("clip.avi");
  wingman::testing::write_test_video(video, kFrames, 320, 240, 30.0);
  const std::string cfg = dir.file("cam.yaml");
  std::ofstream(cfg) << "source: {kind: file}\nfile: {path: " << video
                     << ", mode: fast, start_utime: 1700000000000000}\n";
  const std::string frames = dir.file("frames.lcmlog");
  const auto r =
      run({bin_path("wingman-camera-driver"), "--config", cfg, "--lcm-out", "file://" + frames + "?mode=w"}, 30s);
  if (r.exit_code != 0) throw std::runtime_error(r.err);
  std::vector<LogEvent> events;
  for (auto& e : read_log(frames)) {
    if (e.channel == "IMAGE_CAM0") events.push_back(e);
  }
  wingman::image_t bad{};
  bad.utime = 1700000001000000;
  bad.width = 320;
  bad.height = 240;
  bad.stride = 100;  // shorter than a row of BGR8
  bad.pixel_format = wingman::image_t::BGR8;
  bad.data.assign(100 * 240, 0);
  bad.size = static_cast<int32_t>(bad.data.size());
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", bad, 1));
  events.push_back({2, "IMAGE_CAM0", {9, 9, 9}});
  const std::string path = dir.file("in.lcmlog");
  wingman::testing::write_log(path, events);
  return path;
}

struct DetectorRun {
  std::vector<wingman::detections_t> detections;
  wingman::status_t status;          ///< the last heartbeat
  std::vector<std::string> details;  ///< every heartbeat's detail, in order
};

DetectorRun run_detector(const TempDir& dir, const std::string& in, const std::string& weights,
                         const std::string& backend, const std::string& name) {
  const std::string cfg = dir.file(name + ".yaml");
  std::ofstream(cfg) << "model: {cfg: builtin:tiny-yolo-thesis, weights: " << weights << ", backend: " << backend
                     << "}\ninput: {mode: replay}\n";
  const std::string out = dir.file(name + ".lcmlog");
  const auto r = run({bin_path("wingman-detector"), "--config", cfg, "--lcm-in", "file://" + in + "?speed=0",
                      "--lcm-out", "file://" + out + "?mode=w"},
                     240s);  // a bound: seconds here, over 120 s under ThreadSanitizer beside other work
  if (r.exit_code != 0) throw std::runtime_error("detector failed: " + r.err);
  DetectorRun result;
  for (const auto& e : read_log(out)) {
    if (e.channel == "DETECTIONS_CAM0") {
      wingman::detections_t d;
      d.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      result.detections.push_back(d);
    } else if (e.channel == "STATUS_DETECTOR") {
      result.status.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      result.details.push_back(result.status.detail);
    }
  }
  return result;
}

TEST(DetectorProcess, OpenClBackendPublishesOneDetectionsPerGoodFrameAndCountsBadOnes) {
  TempDir dir;
  const std::string weights = write_random_weights(dir);
  const std::string in = write_input_log(dir);
  const DetectorRun a = run_detector(dir, in, weights, "opencl", "a");
  ASSERT_EQ(a.detections.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    const auto& d = a.detections[i];
    EXPECT_EQ(d.seq, i);
    EXPECT_EQ(d.utime, 1700000000000000 + static_cast<int64_t>(i * 1e6 / 30.0 + 0.5));
    EXPECT_EQ(d.image_width, 320);
    EXPECT_EQ(d.image_height, 240);
    EXPECT_GT(d.inference_latency_us, 0);
    for (const auto& b : d.detections) {
      EXPECT_GE(b.confidence, 0.2f);  // detection.p_thresh
      EXPECT_GT(b.w, 0.0f);
    }
  }
  EXPECT_EQ(a.status.drops_total, 2) << a.status.last_error;
  int boxes = 0;
  for (const auto& d : a.detections) boxes += d.num_detections;
  std::cout << "random-weight network: " << boxes << " boxes in " << kFrames << " frames\n";

  // Same input, same detections (inference_latency_us is the one wall-clock field).
  const DetectorRun b = run_detector(dir, in, weights, "opencl", "b");
  ASSERT_EQ(b.detections.size(), a.detections.size());
  for (size_t i = 0; i < a.detections.size(); ++i) {
    ASSERT_EQ(b.detections[i].num_detections, a.detections[i].num_detections) << "frame " << i;
    for (int k = 0; k < a.detections[i].num_detections; ++k) {
      EXPECT_EQ(b.detections[i].detections[k].cx, a.detections[i].detections[k].cx);
      EXPECT_EQ(b.detections[i].detections[k].confidence, a.detections[i].detections[k].confidence);
    }
  }
}

TEST(DetectorProcess, AutoInReplayModeRunsOpenClUntimedWithTheOpenClRunsBoxes) {
  // model.backend auto in replay mode does not time the backends (two replays could choose differently): OpenCL
  // whenever a device is usable, so its boxes are the opencl run's, byte for byte.
  TempDir dir;
  const std::string weights = write_random_weights(dir);
  const std::string in = write_input_log(dir);
  const DetectorRun a = run_detector(dir, in, weights, "auto", "auto");
  bool said = false;
  for (const auto& d : a.details) said = said || d.find("(auto, not timed: ") != std::string::npos;
  ASSERT_TRUE(said) << "no heartbeat saying why auto chose; the last: " << a.status.detail;
  for (const auto& d : a.details) {
    if (d.find("no usable OpenCL device") != std::string::npos) GTEST_SKIP() << "no OpenCL device here: " << d;
  }
  const DetectorRun o = run_detector(dir, in, weights, "opencl", "opencl");
  ASSERT_EQ(a.detections.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(o.detections.size(), a.detections.size());
  for (size_t i = 0; i < a.detections.size(); ++i) {
    wingman::detections_t x = a.detections[i], y = o.detections[i];
    x.inference_latency_us = y.inference_latency_us = 0;  // the one wall-clock field
    std::vector<uint8_t> bx(static_cast<size_t>(x.getEncodedSize())), by(static_cast<size_t>(y.getEncodedSize()));
    x.encode(bx.data(), 0, static_cast<int>(bx.size()));
    y.encode(by.data(), 0, static_cast<int>(by.size()));
    EXPECT_EQ(bx, by) << "frame " << i;
  }
}

TEST(DetectorProcess, CpuBackendHandlesTheSameStream) {
  TempDir dir;
  const DetectorRun c = run_detector(dir, write_input_log(dir), write_random_weights(dir), "cpu", "c");
  EXPECT_EQ(c.detections.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(c.status.drops_total, 2) << c.status.last_error;
}

TEST(DetectorProcess, MissingWeightsFileIsAOneLineErrorNamingIt) {
  TempDir dir;
  const std::string cfg = dir.file("d.yaml");
  std::ofstream(cfg) << "model: {cfg: builtin:tiny-yolo-thesis, weights: /nonexistent/x.weights, backend: cpu}\n";
  const auto r = run({bin_path("wingman-detector"), "--config", cfg, "--lcm-url", "memq://"}, 30s);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("wingman-detector: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/x.weights"), std::string::npos) << r.err;
}

// Issue 33, finding 1: a frame whose seq jumps 2^62 ahead used to make the detector loop once per "missing" frame
// (it never ended and ignored SIGTERM). The gap is one count now: the run ends at once and reports it.
TEST(DetectorProcess, ASequenceJumpOfTwoToTheSixtySecondIsCountedAtOnceNotLoopedOver) {
  TempDir dir;
  std::vector<LogEvent> events;
  for (const int64_t seq : {int64_t{0}, int64_t{1} << 62}) {
    wingman::image_t img{};
    img.utime = 1700000000000000 + (seq == 0 ? 0 : 33333);
    img.seq = seq;
    img.width = 320;
    img.height = 240;
    img.stride = 3 * 320;
    img.pixel_format = wingman::image_t::BGR8;
    img.data.assign(static_cast<size_t>(img.stride) * 240, 40);
    img.size = static_cast<int32_t>(img.data.size());
    events.push_back(wingman::testing::make_event("IMAGE_CAM0", img, img.utime));
  }
  const std::string in = dir.file("seq_jump_in.lcmlog");
  wingman::testing::write_log(in, events);
  const auto t0 = std::chrono::steady_clock::now();
  const DetectorRun r = run_detector(dir, in, write_random_weights(dir), "cpu", "jump");  // throws on a timeout
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "detector over a 2^62 seq jump: " << seconds << " s\n";
  ASSERT_EQ(r.detections.size(), 2u);
  EXPECT_EQ(r.detections[1].seq, int64_t{1} << 62);
  EXPECT_EQ(r.status.drops_total, (int64_t{1} << 62) - 1) << r.status.last_error;
  EXPECT_NE(r.status.last_error.find("4611686018427387903 frame(s) missing before seq 4611686018427387904"),
            std::string::npos)
      << r.status.last_error;
}

}  // namespace
