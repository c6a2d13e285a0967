// SPDX-License-Identifier: MIT
// Cost of one camera frame on the message path, per stage: frame -> image_t, encode (publish side),
// decode + validate (subscriber side), and MJPEG decoding, at the resolutions the pipeline uses.
// Run: build/tests/bench_message_path --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <wingman/camera_driver/camera_driver.hpp>
#include <wingman/common/message_validation.hpp>

#include <opencv2/imgcodecs.hpp>

#include <random>

namespace {

namespace cd = wingman::camera_driver;

cd::Frame make_frame(int width, int height, cd::PixelFormat format) {
  const int bpp = format == cd::PixelFormat::kYuyv ? 2 : 3;
  cd::Frame f;
  f.utime = 1700000000000000;
  f.seq = 1;
  f.width = width;
  f.height = height;
  f.stride = width * bpp;
  f.format = format;
  f.data.resize(static_cast<size_t>(f.stride) * height);
  std::mt19937 rng(42);
  for (auto& b : f.data) b = static_cast<uint8_t>(rng());
  return f;
}

void Args(benchmark::internal::Benchmark* b) { b->Args({640, 480})->Args({1280, 720})->Unit(benchmark::kMicrosecond); }

void BM_FrameToImageMessage(benchmark::State& state) {
  const cd::Frame frame =
      make_frame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), cd::PixelFormat::kBgr8);
  for (auto _ : state) {
    wingman::image_t msg = cd::to_image_message(frame, 0);
    benchmark::DoNotOptimize(msg.data.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(frame.data.size()));
}
BENCHMARK(BM_FrameToImageMessage)->Apply(Args);

void BM_EncodeImage(benchmark::State& state) {
  const wingman::image_t msg = cd::to_image_message(
      make_frame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), cd::PixelFormat::kBgr8), 0);
  std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
  for (auto _ : state) {
    benchmark::DoNotOptimize(msg.encode(buf.data(), 0, static_cast<int>(buf.size())));
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(buf.size()));
}
BENCHMARK(BM_EncodeImage)->Apply(Args);

void BM_DecodeAndValidateImage(benchmark::State& state) {
  const wingman::image_t msg = cd::to_image_message(
      make_frame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), cd::PixelFormat::kBgr8), 0);
  std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  for (auto _ : state) {
    wingman::image_t in;
    benchmark::DoNotOptimize(in.decode(buf.data(), 0, static_cast<int>(buf.size())));
    benchmark::DoNotOptimize(wingman::common::validate_message(in));
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(buf.size()));
}
BENCHMARK(BM_DecodeAndValidateImage)->Apply(Args);

void BM_DecodeMjpeg(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  // A smooth gradient compresses like a camera image (random noise would not).
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at<cv::Vec3b>(y, x) = cv::Vec3b(x & 0xff, y & 0xff, (x + y) & 0xff);
  cd::Frame jpeg;
  jpeg.width = w;
  jpeg.height = h;
  jpeg.format = cd::PixelFormat::kMjpeg;
  cv::imencode(".jpg", img, jpeg.data);
  cd::Frame bgr;
  for (auto _ : state) {
    const std::string err = cd::decode_mjpeg(jpeg, bgr);
    if (!err.empty()) state.SkipWithError(err.c_str());
    benchmark::DoNotOptimize(bgr.data.data());
  }
}
BENCHMARK(BM_DecodeMjpeg)->Apply(Args);

}  // namespace

BENCHMARK_MAIN();
