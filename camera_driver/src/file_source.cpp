// SPDX-License-Identifier: MIT
// FileSource: OpenCV VideoCapture or imread over a sorted image list, paced or as fast as possible.
#include "wingman/camera_driver/file_source.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <unistd.h>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace wingman::camera_driver {
namespace fs = std::filesystem;

namespace {

constexpr double kDefaultFps = 30.0;
constexpr double kMaxFps = 1000.0;

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_image_file(const fs::path& p) {
  const auto& exts = image_extensions();
  return std::find(exts.begin(), exts.end(), lower_extension(p)) != exts.end();
}

/// Opens `path` with FFmpeg, else GStreamer, else OpenCV's own MJPEG AVI reader (file backends only: not
/// CAP_ANY, which would also try cameras and image-sequence patterns), with OpenCV's
/// logging silenced meanwhile: backends that fail print multi-line noise; we report one line.
bool open_video(cv::VideoCapture& capture, const std::string& path) {
  const auto previous = cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  bool ok = false;
  for (int api : {cv::CAP_FFMPEG, cv::CAP_GSTREAMER, cv::CAP_OPENCV_MJPEG}) {
    capture.release();
    try {
      ok = capture.open(path, api) && capture.isOpened();
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (ok) break;
  }
  cv::utils::logging::setLogLevel(previous);
  return ok;
}

}  // namespace

const std::vector<std::string>& image_extensions() {
  static const std::vector<std::string> kExts = {".png", ".jpg", ".jpeg", ".bmp", ".pgm",
                                                 ".ppm", ".pnm", ".tif",  ".tiff"};
  return kExts;
}

std::vector<std::string> FileSourceOptions::validate(bool require_path) const {
  using common::problem;
  std::vector<std::string> p;
  if (require_path && path.empty()) {
    p.push_back(problem("file.path", path, "must name a video file or an image folder when source.kind is file"));
  }
  if (mode != "realtime" && mode != "fast") p.push_back(problem("file.mode", mode, "must be realtime or fast"));
  if (!std::isfinite(fps) || fps < 0 || fps > kMaxFps) {
    p.push_back(problem("file.fps", fps, "must be in [0, 1000] frames per second (0 = from the video)"));
  }
  if (start_utime < 0) {
    p.push_back(problem("file.start_utime", static_cast<double>(start_utime),
                        "must be >= 0 microseconds since the epoch (0 = wall clock at open)"));
  }
  if (pixel_format != "BGR8" && pixel_format != "GRAY8") {
    p.push_back(problem("file.pixel_format", pixel_format, "must be BGR8 or GRAY8"));
  }
  return p;
}

struct FileSource::Impl {
  std::vector<std::string> images;  // image list mode when non-empty
  bool image_mode = false;
  cv::VideoCapture capture;
  bool have_pending = false;  // a frame grabbed in open() and not yet delivered
  bool ended = false;
  size_t next_image = 0;          // image list: index of the next file
  int64_t index = 0;              // frames read since open (seq of the next frame)
  int64_t decoded_this_pass = 0;  // frames decoded since the last (re)start of the file
  int64_t start_utime = 0;        // fast mode: utime of frame 0
  int64_t anchor_index = 0;       // realtime: frame index at which the schedule was (re)started
  int64_t anchor_mono_us = 0;     // realtime: monotonic time of frame anchor_index
  int64_t anchor_real_us = 0;     // realtime: wall-clock time of frame anchor_index
  std::string kind;               // "video", "image folder", "image"
};

FileSource::FileSource(FileSourceOptions options, std::shared_ptr<Clock> clock)
    : options_(std::move(options)), clock_(std::move(clock)), impl_(std::make_unique<Impl>()) {
  if (!clock_) throw std::invalid_argument("FileSource: clock must not be null");
  const auto problems = options_.validate(true);
  if (!problems.empty()) throw std::invalid_argument("FileSource: " + problems.front());
}

FileSource::~FileSource() = default;

bool FileSource::is_image_list() const { return impl_->image_mode; }
const std::vector<std::string>& FileSource::images() const { return impl_->images; }

void FileSource::open() {
  const std::string& path = options_.path;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw std::runtime_error(fmt::format("file {}: does not exist", path));
  Impl& m = *impl_;
  if (fs::is_directory(st)) {
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      if (entry.is_regular_file(ec) && is_image_file(entry.path())) m.images.push_back(entry.path().string());
    }
    if (ec) throw std::runtime_error(fmt::format("file {}: cannot list folder: {}", path, ec.message()));
    std::sort(m.images.begin(), m.images.end());
    if (m.images.empty()) {
      std::string exts;
      for (const auto& e : image_extensions()) exts += (exts.empty() ? "" : " ") + e;
      throw std::runtime_error(fmt::format("file {}: folder holds no images ({})", path, exts));
    }
    m.image_mode = true;
    m.kind = "image folder";
  } else if (is_image_file(path)) {
    m.images.push_back(path);
    m.image_mode = true;
    m.kind = "image";
  } else {
    m.kind = "video";
  }

  double native_fps = 0.0;
  if (m.image_mode) {
    // Check readability up front for a clear error; decoding problems show up as drops later.
    for (const auto& img : m.images) {
      if (::access(img.c_str(), R_OK) != 0) {
        throw std::runtime_error(fmt::format("file {}: cannot read: {}", img, std::strerror(errno)));
      }
    }
  } else {
    if (::access(path.c_str(), R_OK) != 0) {
      throw std::runtime_error(fmt::format("file {}: cannot read: {}", path, std::strerror(errno)));
    }
    if (!open_video(m.capture, path)) {
      throw std::runtime_error(
          fmt::format("file {}: cannot open as a video (not a video file, or no OpenCV backend decodes it)", path));
    }
    if (!m.capture.grab()) {
      throw std::runtime_error(fmt::format("file {}: opened, but no frame could be read from it", path));
    }
    m.have_pending = true;
    native_fps = m.capture.get(cv::CAP_PROP_FPS);
  }

  if (options_.fps > 0) {
    fps_ = options_.fps;
  } else if (std::isfinite(native_fps) && native_fps > 0 && native_fps <= kMaxFps) {
    fps_ = native_fps;
  } else {
    fps_ = kDefaultFps;
    if (!m.image_mode) spdlog::warn("file {}: the video reports no frame rate; playing at {} fps", path, fps_);
  }

  m.start_utime = options_.start_utime > 0 ? options_.start_utime : clock_->realtime_utime();
  m.anchor_index = 0;
  m.anchor_mono_us = clock_->monotonic_utime();
  m.anchor_real_us = clock_->realtime_utime();
  spdlog::info("{}", describe());
}

std::string FileSource::describe() const {
  const Impl& m = *impl_;
  std::string s = fmt::format("file {} ({}", options_.path, m.kind.empty() ? "not open" : m.kind);
  if (m.image_mode && m.images.size() > 1) s += fmt::format(", {} images", m.images.size());
  s += fmt::format(") {} @ {} fps {}{}", options_.pixel_format, fps_, options_.mode, options_.loop ? " loop" : "");
  return s;
}

ReadResult FileSource::read(Frame& out, int timeout_ms) {
  Impl& m = *impl_;
  if (m.kind.empty()) throw std::logic_error("FileSource::read before open()");
  if (m.ended) return ReadResult{ReadStatus::kEnd, 0, "", false};
  const double period_us = 1e6 / fps_;

  // Timing: when is frame m.index due, and what is its utime?
  int64_t utime;
  if (options_.mode == "realtime") {
    const int64_t due = m.anchor_mono_us + std::llround(static_cast<double>(m.index - m.anchor_index) * period_us);
    int64_t now = clock_->monotonic_utime();
    if (now < due) {
      clock_->sleep_us(std::min<int64_t>(due - now, int64_t{std::max(0, timeout_ms)} * 1000));
      now = clock_->monotonic_utime();
      if (now < due) return ReadResult{ReadStatus::kTimeout, 0, "", false};
    } else if (static_cast<double>(now - due) > period_us) {
      // Fell behind by more than a frame: restart the schedule now.
      m.anchor_index = m.index;
      m.anchor_mono_us = now;
      m.anchor_real_us = clock_->realtime_utime();
    }
    utime = m.anchor_real_us + std::llround(static_cast<double>(m.index - m.anchor_index) * period_us);
  } else {
    utime = m.start_utime + std::llround(static_cast<double>(m.index) * period_us);
  }

  // Decode the next frame.
  cv::Mat img;
  std::string name;  // what to blame in a drop
  const int imread_flags = options_.pixel_format == "GRAY8" ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR;
  if (m.image_mode) {
    if (m.next_image >= m.images.size()) {
      if (m.decoded_this_pass == 0) {
        throw std::runtime_error(fmt::format("file {}: none of its {} image{} decodes", options_.path, m.images.size(),
                                             m.images.size() == 1 ? "" : "s"));
      }
      if (!options_.loop) {
        m.ended = true;
        return ReadResult{ReadStatus::kEnd, 0, "", false};
      }
      m.next_image = 0;
      m.decoded_this_pass = 0;
    }
    name = m.images[m.next_image++];
    img = cv::imread(name, imread_flags);
  } else {
    name = options_.path;
    bool grabbed = m.have_pending;
    m.have_pending = false;
    if (!grabbed) grabbed = m.capture.grab();
    if (!grabbed) {
      if (m.decoded_this_pass == 0) {
        throw std::runtime_error(fmt::format("file {}: no frame of the video decodes", options_.path));
      }
      if (!options_.loop) {
        m.ended = true;
        return ReadResult{ReadStatus::kEnd, 0, "", false};
      }
      // Reopen rather than seek: seeking is unreliable across backends and codecs.
      if (!open_video(m.capture, options_.path) || !m.capture.grab()) {
        throw std::runtime_error(fmt::format("file {}: cannot reopen the video to loop", options_.path));
      }
      m.decoded_this_pass = 0;
    }
    if (!m.capture.retrieve(img)) img.release();
  }

  const int64_t seq = m.index++;
  if (img.empty() || img.cols <= 0 || img.rows <= 0) {
    ++stats_.dropped;
    const std::string why =
        m.image_mode ? "cannot decode (unreadable or not an image)" : "frame decodes to an empty image";
    return ReadResult{ReadStatus::kDropped, 1, fmt::format("file {}: frame {} {}", name, seq, why), false};
  }

  // Convert to the published layout: 8-bit BGR or gray.
  if (img.depth() != CV_8U) {
    cv::Mat tmp;
    img.convertTo(tmp, CV_8U, img.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
    img = tmp;
  }
  const bool gray = options_.pixel_format == "GRAY8";
  if (gray && img.channels() != 1) {
    cv::Mat tmp;
    cv::cvtColor(img, tmp, img.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    img = tmp;
  } else if (!gray && img.channels() != 3) {
    cv::Mat tmp;
    cv::cvtColor(img, tmp, img.channels() == 4 ? cv::COLOR_BGRA2BGR : cv::COLOR_GRAY2BGR);
    img = tmp;
  }

  out.utime = utime;
  out.seq = seq;
  out.width = img.cols;
  out.height = img.rows;
  out.format = gray ? PixelFormat::kGray8 : PixelFormat::kBgr8;
  out.stride = img.cols * static_cast<int>(img.elemSize());
  out.data.resize(static_cast<size_t>(out.stride) * static_cast<size_t>(out.height));
  for (int r = 0; r < img.rows; ++r) {
    std::memcpy(out.data.data() + static_cast<size_t>(r) * out.stride, img.ptr(r), static_cast<size_t>(out.stride));
  }
  ++m.decoded_this_pass;
  ++stats_.frames;
  return ReadResult{ReadStatus::kFrame, 0, "", false};
}

}  // namespace wingman::camera_driver
