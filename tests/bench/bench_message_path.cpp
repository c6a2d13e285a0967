// SPDX-License-Identifier: MIT
// Cost of one camera frame on the message path, per stage: frame -> image_t, encode (publish side),
// decode + validate (subscriber side), MJPEG decoding, and the real-time detector's handoff of a frame to its worker
// thread and back (common::LatestWorker), at the resolutions the pipeline uses.
// Run: build/tests/bench_message_path --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <wingman/camera_driver/camera_driver.hpp>
#include <wingman/camera_driver/preview.hpp>
#include <wingman/common/latest_worker.hpp>
#include <wingman/common/message_validation.hpp>

#include <opencv2/imgcodecs.hpp>

#include <condition_variable>
#include <mutex>
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

// The monitoring preview (camera_driver::PreviewMaker), one made per iteration (each frame dated 1 s after the last):
// state.range(2) 0 for a BGR8 frame, 1 for MJPEG; the driver makes one a second, the other frames return at once.
void BM_MakePreview(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at<cv::Vec3b>(y, x) = cv::Vec3b(x & 0xff, y & 0xff, (x + y) & 0xff);
  wingman::image_t frame{};
  frame.width = w;
  frame.height = h;
  if (state.range(2) == 1) {
    frame.pixel_format = wingman::image_t::MJPEG;
    cv::imencode(".jpg", img, frame.data);
  } else {
    frame.pixel_format = wingman::image_t::BGR8;
    frame.stride = 3 * w;
    frame.data.assign(img.data, img.data + img.total() * img.elemSize());
  }
  frame.size = static_cast<int32_t>(frame.data.size());
  cd::PreviewMaker maker(cd::PreviewOptions{});
  for (auto _ : state) {
    frame.utime += 1000000;
    const auto p = maker.offer(frame);
    if (!p) state.SkipWithError("no preview");
    benchmark::DoNotOptimize(p);
  }
}
BENCHMARK(BM_MakePreview)
    ->Args({640, 480, 0})
    ->Args({1280, 720, 0})
    ->Args({640, 480, 1})
    ->Args({1280, 720, 1})
    ->Unit(benchmark::kMicrosecond);

// What the real-time detector's worker does with a frame, besides detecting: keeps its header, frees its pixels.
int64_t keep_header(wingman::image_t& img) {
  std::vector<uint8_t>().swap(img.data);
  return img.seq;
}

// The same work on the calling thread: the copy the real-time handler makes, and the work above (the replay path
// makes no copy).
void BM_HandleInline(benchmark::State& state) {
  const wingman::image_t msg = cd::to_image_message(
      make_frame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), cd::PixelFormat::kBgr8), 0);
  for (auto _ : state) {
    wingman::image_t copy = msg;
    benchmark::DoNotOptimize(keep_header(copy));
  }
}
BENCHMARK(BM_HandleInline)->Apply(Args);

// One frame through the worker thread and back: the copy, offer(), the worker's wake-up, the work above, the wake
// of the owner and take(). Against BM_HandleInline: the cost of the two thread switches.
void BM_HandleOnWorker(benchmark::State& state) {
  const wingman::image_t msg = cd::to_image_message(
      make_frame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), cd::PixelFormat::kBgr8), 0);
  std::mutex mutex;
  std::condition_variable woken;
  int wakes = 0;
  wingman::common::LatestWorker<wingman::image_t, int64_t> worker(keep_header, [&] {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++wakes;
    }
    woken.notify_one();
  });
  int expected = 0;
  for (auto _ : state) {
    worker.offer(msg);
    ++expected;
    {
      std::unique_lock<std::mutex> lock(mutex);
      woken.wait(lock, [&] { return wakes >= expected; });
    }
    benchmark::DoNotOptimize(worker.take().results);
  }
}
BENCHMARK(BM_HandleOnWorker)->Apply(Args)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
