// SPDX-License-Identifier: MIT
// The detector's frame loop (detector::Detector) without LCM: the shipped model on the CPU backend, images and
// tracker windows in, detections_t out; the image clock, the windows' camera and age, and the model-less mode.
#include "wingman/detector/detection_message.hpp"
#include "wingman/detector/detector.hpp"
#include "wingman/detector/model_loader.hpp"
#include "wingman/detector/preprocess.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace wingman::detector;

constexpr int64_t kStart = 1700000000000000;
constexpr int64_t kFrameUs = 33333;
constexpr int kWidth = 320;
constexpr int kHeight = 192;

/// The shipped model on the CPU backend at a small fixed network input (fast, deterministic), a low threshold so that
/// the test image gives boxes.
DetectorOptions cpu_options() {
  DetectorOptions o;
  o.backend = "cpu";
  o.input_size = "320x192";
  o.detection.p_thresh = 0.01;
  o.windows.crop_px = 64;
  return o;
}

/// A BGR8 frame `seq` of camera `camera`: a sky gradient with fixed-seed noise and a dark quad-like shape (a body
/// and four rotors) left of centre.
wingman::image_t frame(int64_t seq, int32_t camera = 0) {
  cv::Mat bgr(kHeight, kWidth, CV_8UC3);
  for (int y = 0; y < kHeight; ++y) bgr.row(y).setTo(cv::Scalar(230 - y / 4, 200 - y / 4, 170 - y / 4));
  cv::Mat noise(kHeight, kWidth, CV_8UC3);
  cv::theRNG().state = 7 + static_cast<uint64_t>(seq);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(6));
  bgr += noise;
  const cv::Point c(120, 90);
  cv::rectangle(bgr, c - cv::Point(10, 4), c + cv::Point(10, 4), cv::Scalar(30, 30, 30), cv::FILLED);
  for (const cv::Point r : {cv::Point(-16, -8), cv::Point(16, -8), cv::Point(-16, 8), cv::Point(16, 8)}) {
    cv::line(bgr, c, c + r, cv::Scalar(40, 40, 40), 2);
    cv::circle(bgr, c + r, 6, cv::Scalar(50, 50, 50), cv::FILLED);
  }
  wingman::image_t m{};
  m.utime = kStart + seq * kFrameUs;
  m.seq = seq;
  m.camera_id = camera;
  m.width = kWidth;
  m.height = kHeight;
  m.stride = kWidth * 3;
  m.pixel_format = wingman::image_t::BGR8;
  m.data.assign(bgr.data, bgr.data + bgr.total() * bgr.elemSize());
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

/// One far (tiny) window of camera `camera` at (cx, cy), predicted for `utime_predicted`.
wingman::track_windows_t far_window(int64_t utime_predicted, int32_t camera = 0, float cx = 120, float cy = 90) {
  wingman::track_windows_t m{};
  m.utime = utime_predicted - kFrameUs;
  m.utime_predicted = utime_predicted;
  m.camera_id = camera;
  m.image_width = kWidth;
  m.image_height = kHeight;
  wingman::track_window_t w{};
  w.track_id = 1;
  w.confirmed = true;
  w.cx = cx;
  w.cy = cy;
  w.w = 2;
  w.h = 1;
  w.sigma_px = 1;
  w.range_m = 30;
  w.confidence = 0.5f;
  m.windows = {w};
  m.num_windows = 1;
  return m;
}

std::vector<uint8_t> encode(const wingman::detections_t& d) {
  std::vector<uint8_t> bytes(static_cast<size_t>(d.getEncodedSize()));
  d.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

/// The message of `image` built by hand from `boxes`, as wingman-detector published it before the class existed.
wingman::detections_t expected_message(const wingman::image_t& image, const std::vector<Box>& boxes, int32_t latency_us,
                                       const std::string& model_id) {
  wingman::detections_t out{};
  out.utime = image.utime;
  out.seq = image.seq;
  out.camera_id = image.camera_id;
  out.image_width = image.width;
  out.image_height = image.height;
  out.source = wingman::detections_t::SOURCE_CNN;
  out.inference_latency_us = latency_us;
  out.model_id = model_id;
  for (const auto& b : boxes) out.detections.push_back(to_detection(b));
  out.num_detections = static_cast<int32_t>(out.detections.size());
  return out;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

cv::Mat bgr_of(const wingman::image_t& img) {
  std::string error;
  cv::Mat bgr = image_to_bgr(img, &error);
  EXPECT_EQ(error, "");
  return bgr;
}

TEST(Detector, EachImageGivesTheDetectionsOfItsPixelsWithItsHeaderByteForByte) {
  const DetectorOptions o = cpu_options();
  Detector det(o);
  ASSERT_TRUE(det.has_model());
  EXPECT_EQ(det.degraded(), "");
  EXPECT_FALSE(det.windows_enabled());
  // The start-up build says which backend runs, and why: the heartbeat's detail.
  const auto notes = det.take_notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].text.find("network input 320x192"), std::string::npos) << notes[0].text;
  EXPECT_FALSE(notes[0].state.empty());
  EXPECT_TRUE(det.take_notes().empty());

  // The same pipeline by hand: the class adds nothing to the boxes but the message around them.
  SizedDetector reference(
      o.detection, load_model(o.cfg, o.weights), *InputSize::parse(o.input_size),
      [&](const DarknetModel& m) { return make_backend("cpu", m, o.opencl, o.opencl.max_batch, nullptr); });
  const std::string model_id = weights_model_id(o.weights);
  int boxes = 0;
  for (int64_t seq : {3, 4, 6}) {
    const wingman::image_t img = frame(seq, 2);
    const auto out = det.on_image(img);
    ASSERT_TRUE(out.has_value());
    EXPECT_EQ(out->utime, img.utime);
    EXPECT_EQ(out->seq, seq);
    EXPECT_EQ(out->camera_id, 2);
    EXPECT_EQ(out->image_width, kWidth);
    EXPECT_EQ(out->image_height, kHeight);
    EXPECT_EQ(out->model_id, model_id);
    EXPECT_GE(out->inference_latency_us, 0);
    boxes += out->num_detections;
    const auto want = expected_message(img, reference.detect(bgr_of(img)), out->inference_latency_us, model_id);
    EXPECT_EQ(encode(*out), encode(want)) << "seq " << seq;
  }
  EXPECT_GT(boxes, 0) << "the test image gives no box: nothing was compared";
  EXPECT_TRUE(det.take_notes().empty());  // no other network was built
}

TEST(Detector, AnImageDatedFarAheadOrOutOfOrderIsRefusedNamingImageUtimeAndLeavesTheClock) {
  Detector det(cpu_options());
  det.take_notes();
  ASSERT_TRUE(det.on_image(frame(0)));
  ASSERT_TRUE(det.on_image(frame(1)));
  wingman::image_t ahead = frame(2);
  ahead.utime += 3600LL * 1000000;  // an hour ahead: never the clock's "now"
  const std::string ahead_error = error_of([&] { det.on_image(ahead); });
  EXPECT_NE(ahead_error.find("image_t.utime = " + std::to_string(ahead.utime)), std::string::npos) << ahead_error;
  wingman::image_t behind = frame(3);
  behind.utime = frame(0).utime;  // before the previous frame
  const std::string behind_error = error_of([&] { det.admit(behind); });
  EXPECT_NE(behind_error.find("image_t.utime = " + std::to_string(behind.utime)), std::string::npos) << behind_error;
  const std::string duplicate_error = error_of([&] { det.on_image(frame(1)); });
  EXPECT_NE(duplicate_error.find("image_t.utime"), std::string::npos) << duplicate_error;
  // The next frame in order is detected: the lies moved nothing.
  const auto next = det.on_image(frame(4));
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(next->seq, 4);
}

TEST(Detector, PixelsThatCannotBeReadAreRefused) {
  Detector det(cpu_options());
  wingman::image_t bad = frame(0);
  bad.stride = 100;  // shorter than a row of BGR8
  EXPECT_NE(error_of([&] { det.on_image(bad); }), "");
  EXPECT_TRUE(det.on_image(frame(1)).has_value());
}

TEST(Detector, WindowsOfTheFramesCameraAreSearchedAndAnotherCamerasAreRefusedNamingTheField) {
  DetectorOptions o = cpu_options();
  o.windows.enabled = true;
  Detector det(o);
  ASSERT_TRUE(det.windows_enabled());
  const auto notes = det.take_notes();
  ASSERT_EQ(notes.size(), 2u);  // the single pass's network, then the window's
  EXPECT_NE(notes[1].text.find("network input 64x64"), std::string::npos) << notes[1].text;

  // Before any frame, the camera is not known: windows are kept.
  det.on_windows(far_window(frame(0).utime, 0));
  ASSERT_TRUE(det.on_image(frame(0)));
  EXPECT_EQ(det.window_stats().windows, 1);
  EXPECT_EQ(det.window_stats().crops, 1);
  // Another camera's windows: refused naming the field, and the newest windows stay those of camera 0.
  EXPECT_EQ(error_of([&] { det.on_windows(far_window(frame(1).utime, 3)); }),
            "track_windows_t.camera_id = 3: the frames are camera 0");
  ASSERT_TRUE(det.on_image(frame(1)));  // 33 ms after the prediction: inside windows.max_age_s
  EXPECT_EQ(det.window_stats().windows, 2);

  // The windows' boxes merged as WindowDetector merges them.
  det.on_windows(far_window(frame(2).utime, 0));
  const wingman::image_t img = frame(2);
  const auto out = det.on_image(img);
  ASSERT_TRUE(out.has_value());
  auto sized = [&](const DarknetModel& m) { return make_backend("cpu", m, o.opencl, o.opencl.max_batch, nullptr); };
  const DarknetModel model = load_model(o.cfg, o.weights);
  SizedDetector reference(o.detection, model, *InputSize::parse(o.input_size), sized);
  WindowDetector windows(o.windows, o.detection, model, sized);
  const cv::Mat bgr = bgr_of(img);
  const cv::Size size(bgr.cols, bgr.rows);
  const auto search =
      windows_to_search(far_window(img.utime, 0), img.utime, size, 0, reference.net_px_per_image_px(size), o.windows);
  ASSERT_EQ(search.size(), 1u);
  const auto boxes = windows.detect(bgr, reference.detect(bgr), search);
  EXPECT_EQ(encode(*out), encode(expected_message(img, boxes, out->inference_latency_us, weights_model_id(o.weights))));
  EXPECT_EQ(det.window_stats().windows, 3);
}

TEST(Detector, WindowsPredictedFurtherThanMaxAgeFromTheExposureAreNotSearched) {
  DetectorOptions o = cpu_options();
  o.windows.enabled = true;
  o.windows.max_age_s = 0.5;
  Detector det(o);
  det.on_windows(far_window(frame(0).utime));
  ASSERT_TRUE(det.on_image(frame(0)));
  EXPECT_EQ(det.window_stats().windows, 1);
  // 0.6 s after the prediction: stale, the frame is the single pass's alone.
  wingman::image_t late = frame(1);
  late.utime = frame(0).utime + 600000;
  ASSERT_TRUE(det.on_image(late));
  EXPECT_EQ(det.window_stats().windows, 1);
  // Windows predicted 0.6 s after the frame: not searched either.
  det.on_windows(far_window(late.utime + 2 * 600000));
  wingman::image_t next = frame(2);
  next.utime = late.utime + 600000;
  ASSERT_TRUE(det.on_image(next));
  EXPECT_EQ(det.window_stats().windows, 1);
  EXPECT_EQ(det.window_stats().crops, 1);
}

TEST(Detector, WithoutWeightsImagesAreOnlyCheckedByTheirTime) {
  DetectorOptions o = cpu_options();
  o.weights = "";
  o.windows.enabled = true;
  Detector det(o);
  EXPECT_FALSE(det.has_model());
  EXPECT_FALSE(det.windows_enabled());
  EXPECT_EQ(det.degraded(), "no model.weights configured: images are checked and counted only");
  EXPECT_TRUE(det.take_notes().empty());  // nothing was built
  EXPECT_FALSE(det.on_image(frame(0)).has_value());
  EXPECT_FALSE(det.on_image(frame(1)).has_value());
  EXPECT_NE(error_of([&] { det.on_image(frame(1)); }).find("image_t.utime"), std::string::npos);
  EXPECT_THROW(det.detect(frame(2)), std::logic_error);
}

TEST(Detector, InvalidOptionsAreNamed) {
  DetectorOptions o = cpu_options();
  o.backend = "gpu";
  const std::string e = error_of([&] { Detector det(o); });
  EXPECT_NE(e.find("model.backend"), std::string::npos) << e;
}

TEST(Detector, AutoRepeatableTakesOpenClWithoutTiming) {
  // AutoChoice::kRepeatable (the detector in replay mode, the offline tools): OpenCL whenever a device is usable, not
  // timed, so that two runs take the same backend (a timed choice can differ when the two are close, and their boxes
  // differ in the 4th decimal). The detector process's replay mode: DetectorProcess.* and test_replay.
  const DetectorOptions o = cpu_options();
  const DarknetModel model = load_model(o.cfg, o.weights);
  std::string why;
  const auto backend = make_backend("auto", model, o.opencl, 1, &why, AutoChoice::kRepeatable);
  ASSERT_NE(backend, nullptr);
  if (why.find("no usable OpenCL device") != std::string::npos) {
    EXPECT_EQ(why.rfind("backend cpu (auto, not timed: no usable OpenCL device: ", 0), 0u) << why;
    GTEST_SKIP() << "no OpenCL device here: " << why;
  }
  EXPECT_EQ(backend->name().rfind("opencl", 0), 0u) << backend->name();
  EXPECT_EQ(why, "backend " + backend->name() +
                     " (auto, not timed: OpenCL whenever a device is usable, so that runs repeat)");
}

TEST(Detector, AutoTimesBothBackendsInTurnAndRunsTheOneItSaysWasFaster) {
  // model.backend auto on PoCL: both backends timed in turn, each one's fastest forward compared; the backend it
  // returns is the one its line says was faster (by the numbers it prints), and it says how many forwards it timed.
  const DetectorOptions o = cpu_options();
  const DarknetModel model = load_model(o.cfg, o.weights);
  std::string why;
  const auto backend = make_backend("auto", model, o.opencl, 1, &why);
  ASSERT_NE(backend, nullptr);
  if (why.find("no usable OpenCL device") != std::string::npos) GTEST_SKIP() << "no OpenCL device here: " << why;
  double ms_ocl = 0, ms_cpu = 0;
  int runs = 0;
  const size_t at = why.find("fastest of ");
  ASSERT_NE(at, std::string::npos) << why;
  ASSERT_EQ(std::sscanf(why.c_str() + at, "fastest of %d forward(s) each, in turn: %lf ms opencl", &runs, &ms_ocl), 2)
      << why;
  const size_t vs = why.find(" vs ");
  ASSERT_NE(vs, std::string::npos) << why;
  ASSERT_EQ(std::sscanf(why.c_str() + vs, " vs %lf ms cpu", &ms_cpu), 1) << why;
  EXPECT_TRUE(runs == 1 || runs == 3) << why;  // 1: the CPU lost the first turn by 1.5x or more
  EXPECT_GT(ms_ocl, 0.0);
  EXPECT_GT(ms_cpu, 0.0);
  const bool opencl_chosen = backend->name().rfind("opencl", 0) == 0;
  EXPECT_EQ(opencl_chosen, ms_ocl <= ms_cpu) << why << " -> " << backend->name();
  EXPECT_EQ(why.rfind("backend " + backend->name() + " (auto: ", 0), 0u) << why;
}

}  // namespace
