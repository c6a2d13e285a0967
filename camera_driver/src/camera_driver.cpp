// SPDX-License-Identifier: MIT
// CameraDriver: frame checks, MJPEG decoding and encoding, image_t conversion and the source factory.
#include "wingman/camera_driver/camera_driver.hpp"

#include "wingman/camera_driver/file_source.hpp"
#include "wingman/camera_driver/v4l2_source.hpp"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace wingman::camera_driver {

namespace {
wingman::image_t header_of(const Frame& frame, int32_t camera_id) {
  wingman::image_t msg;
  msg.utime = frame.utime;
  msg.seq = frame.seq;
  msg.camera_id = camera_id;
  msg.width = frame.width;
  msg.height = frame.height;
  msg.stride = frame.format == PixelFormat::kMjpeg ? 0 : frame.stride;
  msg.pixel_format = static_cast<int8_t>(frame.format);
  msg.size = static_cast<int32_t>(frame.data.size());
  return msg;
}
}  // namespace

wingman::image_t to_image_message(const Frame& frame, int32_t camera_id) {
  wingman::image_t msg = header_of(frame, camera_id);
  msg.data = frame.data;
  return msg;
}

wingman::image_t to_image_message(Frame&& frame, int32_t camera_id) {
  wingman::image_t msg = header_of(frame, camera_id);
  msg.data = std::move(frame.data);
  frame.data.clear();
  return msg;
}

std::string decode_mjpeg(const Frame& jpeg, Frame& bgr) {
  const cv::Mat buf(1, static_cast<int>(jpeg.data.size()), CV_8UC1, const_cast<uint8_t*>(jpeg.data.data()));
  cv::Mat img;
  try {
    img = cv::imdecode(buf, cv::IMREAD_COLOR);
  } catch (const cv::Exception& e) {
    img.release();
  }
  if (img.empty())
    return fmt::format("frame seq {}: MJPEG stream ({} bytes) does not decode", jpeg.seq, jpeg.data.size());
  if (img.cols != jpeg.width || img.rows != jpeg.height) {
    return fmt::format("frame seq {}: MJPEG decodes to {}x{}, the device said {}x{}", jpeg.seq, img.cols, img.rows,
                       jpeg.width, jpeg.height);
  }
  bgr.utime = jpeg.utime;
  bgr.seq = jpeg.seq;
  bgr.width = img.cols;
  bgr.height = img.rows;
  bgr.format = PixelFormat::kBgr8;
  bgr.stride = img.cols * 3;
  bgr.data.resize(static_cast<size_t>(bgr.stride) * static_cast<size_t>(bgr.height));
  for (int r = 0; r < img.rows; ++r) {
    std::memcpy(bgr.data.data() + static_cast<size_t>(r) * bgr.stride, img.ptr(r), static_cast<size_t>(bgr.stride));
  }
  return "";
}

std::string encode_mjpeg(const Frame& raw, int quality, Frame& jpeg) {
  auto* pixels = const_cast<uint8_t*>(raw.data.data());
  const auto stride = static_cast<size_t>(raw.stride);
  cv::Mat img;
  switch (raw.format) {
    case PixelFormat::kGray8:
      img = cv::Mat(raw.height, raw.width, CV_8UC1, pixels, stride);
      break;
    case PixelFormat::kBgr8:
      img = cv::Mat(raw.height, raw.width, CV_8UC3, pixels, stride);
      break;
    case PixelFormat::kYuyv:
      cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC2, pixels, stride), img, cv::COLOR_YUV2BGR_YUYV);
      break;
    case PixelFormat::kMjpeg:
      return fmt::format("frame seq {}: already MJPEG", raw.seq);
  }
  bool ok = false;
  try {
    ok = cv::imencode(".jpg", img, jpeg.data, {cv::IMWRITE_JPEG_QUALITY, quality});
  } catch (const cv::Exception& e) {
    ok = false;
  }
  if (!ok || jpeg.data.empty())
    return fmt::format("frame seq {}: {}x{} {} does not encode as JPEG", raw.seq, raw.width, raw.height,
                       pixel_format_name(raw.format));
  jpeg.utime = raw.utime;
  jpeg.seq = raw.seq;
  jpeg.width = raw.width;
  jpeg.height = raw.height;
  jpeg.format = PixelFormat::kMjpeg;
  jpeg.stride = 0;
  return "";
}

void downscale_frame(const Frame& raw, int max_width, Frame& small) {
  auto* pixels = const_cast<uint8_t*>(raw.data.data());
  const auto stride = static_cast<size_t>(raw.stride);
  cv::Mat img;
  if (raw.format == PixelFormat::kGray8) {
    img = cv::Mat(raw.height, raw.width, CV_8UC1, pixels, stride);
  } else if (raw.format == PixelFormat::kBgr8) {
    img = cv::Mat(raw.height, raw.width, CV_8UC3, pixels, stride);
  } else {  // YUYV
    cv::cvtColor(cv::Mat(raw.height, raw.width, CV_8UC2, pixels, stride), img, cv::COLOR_YUV2BGR_YUYV);
  }
  const int height =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(raw.height) * max_width / raw.width)));
  small.format = img.channels() == 1 ? PixelFormat::kGray8 : PixelFormat::kBgr8;
  small.width = max_width;
  small.height = height;
  small.stride = max_width * img.channels();
  small.data.resize(static_cast<size_t>(small.stride) * static_cast<size_t>(height));
  cv::Mat dst(height, max_width, img.type(), small.data.data(), static_cast<size_t>(small.stride));
  cv::resize(img, dst, dst.size(), 0, 0, cv::INTER_AREA);
  small.utime = raw.utime;
  small.seq = raw.seq;
}

std::unique_ptr<FrameSource> make_source(const CameraDriverOptions& options, std::shared_ptr<V4l2Io> io,
                                         std::shared_ptr<Clock> clock) {
  const auto problems = options.validate();
  if (!problems.empty()) throw std::invalid_argument(problems.front());
  if (options.source_kind == "file") return std::make_unique<FileSource>(options.file, std::move(clock));
  return std::make_unique<V4l2Source>(options.v4l2, std::move(io), std::move(clock));
}

CameraDriver::CameraDriver(OutputOptions options, std::unique_ptr<FrameSource> source)
    : options_(std::move(options)),
      source_(std::move(source)),
      time_offset_us_(std::llround(options_.time_offset_s * 1e6)) {
  if (!source_) throw std::invalid_argument("CameraDriver: source must not be null");
  if (const auto bad = options_.validate(); !bad.empty()) throw std::invalid_argument(bad.front());
}

void CameraDriver::open() { source_->open(); }

std::string CameraDriver::describe() const {
  std::string s = source_->describe();
  if (time_offset_us_ != 0) s += fmt::format(", stamps moved by {:g} s (output.time_offset_s)", options_.time_offset_s);
  return s;
}

bool CameraDriver::done() const { return ended_ || (options_.max_frames > 0 && frames_out_ >= options_.max_frames); }

DriverStep CameraDriver::step(int timeout_ms) {
  DriverStep step;
  const ReadResult r = source_->read(frame_, timeout_ms);
  step.status = r.status;
  step.lost = r.lost;
  step.reason = r.reason;
  step.reconnected = r.reconnected;
  if (r.status == ReadStatus::kEnd) ended_ = true;
  if (r.status != ReadStatus::kFrame) return step;

  const auto t0 = std::chrono::steady_clock::now();
  auto drop = [&](const std::string& why) {
    ++driver_drops_;
    step.status = ReadStatus::kDropped;
    step.lost += 1;
    step.reason = step.reason.empty() ? why : step.reason + "; " + why;
    return step;
  };
  if (std::string bad = check_frame(frame_); !bad.empty()) return drop(source_->describe() + ": " + bad);
  Frame* out = &frame_;
  if (options_.decode_mjpeg && frame_.format == PixelFormat::kMjpeg) {
    if (std::string bad = decode_mjpeg(frame_, decoded_); !bad.empty()) return drop(source_->describe() + ": " + bad);
    out = &decoded_;
  }
  if (options_.max_width > 0 && out->format != PixelFormat::kMjpeg && out->width > options_.max_width) {
    downscale_frame(*out, options_.max_width, scaled_);
    out = &scaled_;
  }
  if (options_.encoding == "mjpeg" && out->format != PixelFormat::kMjpeg) {
    if (std::string bad = encode_mjpeg(*out, options_.jpeg_quality, encoded_); !bad.empty())
      return drop(source_->describe() + ": " + bad);
    out = &encoded_;
  }
  step.image = to_image_message(std::move(*out), options_.camera_id);  // the next read refills the frame
  step.image.utime += time_offset_us_;
  ++frames_out_;
  step.convert_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return step;
}

}  // namespace wingman::camera_driver
