// SPDX-License-Identifier: MIT
// `wingman dataset from-log`: a flight log's camera frames and ground-truth boxes as a YOLO dataset.
#include "wingman/tools/dataset_from_log.hpp"

#include "log_progress.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/common/message_validation.hpp>
#include <wingman/detector/preprocess.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>

namespace wingman::tools {
namespace fs = std::filesystem;
namespace {

/// Frames waiting for their partner message are kept for this many seqs at most (the simulator publishes an image
/// and its ground truth in the same step, so a partner arrives within a few messages or never).
constexpr int64_t kPairWindow = 64;

struct Pending {
  std::map<int64_t, wingman::image_t> images;        // by image seq
  std::map<int64_t, wingman::ground_truth_t> truth;  // by image_seq
};

void validate(const DatasetFromLogRequest& r) {
  if (r.logs.empty()) throw std::invalid_argument("no log given: name one or more LCM logs");
  if (r.out_dir.empty()) throw std::invalid_argument("--out: a dataset folder is required");
  if (r.split != "train" && r.split != "val")
    throw std::invalid_argument(fmt::format("--split '{}': expected train or val", r.split));
  if (r.every < 1) throw std::invalid_argument(fmt::format("--every {}: must be >= 1", r.every));
  if (!(r.min_box_px >= 0.0)) throw std::invalid_argument(fmt::format("--min-box-px {}: must be >= 0", r.min_box_px));
  if (r.image_format != "jpg" && r.image_format != "png")
    throw std::invalid_argument(fmt::format("--format '{}': expected jpg or png", r.image_format));
  if (r.jpeg_quality < 1 || r.jpeg_quality > 100)
    throw std::invalid_argument(fmt::format("--jpeg-quality {}: must be in 1..100", r.jpeg_quality));
}

/// The visible, finite boxes of `truth` on the image's camera, clipped to the image, as YOLO labels.
std::vector<training::LabeledBox> labels_of(const wingman::ground_truth_t& truth, const wingman::image_t& image,
                                            double min_box_px) {
  std::vector<training::LabeledBox> labels;
  const double W = image.width, H = image.height;
  for (const auto& b : truth.boxes) {
    if (!b.visible || b.camera_id != image.camera_id) continue;
    if (!std::isfinite(b.cx) || !std::isfinite(b.cy) || !std::isfinite(b.w) || !std::isfinite(b.h)) continue;
    const double x0 = std::clamp(b.cx - 0.5 * b.w, 0.0, W), x1 = std::clamp(b.cx + 0.5 * b.w, 0.0, W);
    const double y0 = std::clamp(b.cy - 0.5 * b.h, 0.0, H), y1 = std::clamp(b.cy + 0.5 * b.h, 0.0, H);
    if (x1 - x0 < std::max(min_box_px, 1e-3) || y1 - y0 < std::max(min_box_px, 1e-3)) continue;
    training::LabeledBox l;
    l.cls = 0;
    l.cx = static_cast<float>(0.5 * (x0 + x1) / W);
    l.cy = static_cast<float>(0.5 * (y0 + y1) / H);
    l.w = static_cast<float>((x1 - x0) / W);
    l.h = static_cast<float>((y1 - y0) / H);
    labels.push_back(l);
  }
  return labels;
}

}  // namespace

std::string DatasetFromLogSummary::one_line() const {
  return fmt::format(
      "wrote {} images ({} boxes, {} negatives) to {} in {:.1f} s ({} skipped, {} unmatched, {} undecodable)", images,
      boxes, negatives, out_dir, seconds, skipped, unmatched, undecodable);
}

DatasetFromLogSummary run_dataset_from_log(const DatasetFromLogRequest& request, std::ostream& progress) {
  const auto start = std::chrono::steady_clock::now();
  validate(request);
  const fs::path out(request.out_dir);
  for (const char* kind : {"images", "labels"}) {
    for (const char* split : {"train", "val"}) fs::create_directories(out / kind / split);
  }
  DatasetFromLogSummary summary;
  summary.out_dir = (out / "images" / request.split).string();
  const std::vector<int> params = request.image_format == "jpg"
                                      ? std::vector<int>{cv::IMWRITE_JPEG_QUALITY, request.jpeg_quality}
                                      : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 3};

  for (const std::string& log_path : request.logs) {
    common::LcmLogReader log(log_path);  // a corrupt event throws, naming its byte offset
    const std::string stem = fs::path(log_path).stem().string();
    Pending pending;
    int64_t images_seen = 0, truth_seen = 0, written_here = 0;

    // Writes one image and its labels (or counts it as skipped).
    auto emit = [&](const wingman::image_t& image, const wingman::ground_truth_t& truth) {
      const std::vector<training::LabeledBox> labels = labels_of(truth, image, request.min_box_px);
      if (labels.empty() && !request.keep_negatives) {
        ++summary.skipped;
        return;
      }
      std::string error;
      const cv::Mat bgr = detector::image_to_bgr(image, &error);
      if (bgr.empty()) {
        ++summary.undecodable;
        progress << fmt::format("wingman dataset from-log: {}: image seq {} dropped: {}", log_path, image.seq, error)
                 << std::endl;
        return;
      }
      const std::string name = fmt::format("{}_{:07d}", stem, image.seq);
      const fs::path image_path = out / "images" / request.split / (name + "." + request.image_format);
      const fs::path label_path = out / "labels" / request.split / (name + ".txt");
      if (fs::exists(image_path) || fs::exists(label_path))
        throw std::runtime_error(
            fmt::format("{}: already exists (a log of the same name was added before); "
                        "rename the log or choose a new --out",
                        image_path.string()));
      if (!cv::imwrite(image_path.string(), bgr, params))
        throw std::runtime_error(image_path.string() + ": cannot write the image");
      training::write_yolo_labels(label_path.string(), labels);
      ++summary.images;
      ++written_here;
      summary.boxes += static_cast<int>(labels.size());
      if (labels.empty()) ++summary.negatives;
    };
    // An image is kept by --every on its position among the log's images; its partner may come before or after.
    auto try_pair = [&](int64_t seq) {
      const auto i = pending.images.find(seq);
      const auto t = pending.truth.find(seq);
      if (i == pending.images.end() || t == pending.truth.end()) return;
      emit(i->second, t->second);
      pending.images.erase(i);
      pending.truth.erase(t);
    };
    auto expire = [&](int64_t newest_seq) {
      for (auto it = pending.images.begin(); it != pending.images.end() && it->first < newest_seq - kPairWindow;) {
        ++summary.unmatched;
        it = pending.images.erase(it);
      }
      for (auto it = pending.truth.begin(); it != pending.truth.end() && it->first < newest_seq - kPairWindow;)
        it = pending.truth.erase(it);
    };

    common::Progress read = log_progress(&progress, "wingman dataset from-log: reading " + log_path, log_path);
    while (const common::LcmLogEvent* ev = log.read_next()) {
      read.update(ev->offset, fmt::format("{} images written", written_here));
      if (ev->channel == request.image_channel) {
        wingman::image_t image;
        if (image.decode(ev->data, 0, ev->datalen) < 0 || !common::validate_message(image).empty()) {
          ++summary.undecodable;
          continue;
        }
        if (images_seen++ % request.every != 0) {
          ++summary.skipped;
          continue;
        }
        const int64_t seq = image.seq;
        pending.images[seq] = std::move(image);
        try_pair(seq);
        expire(seq);
      } else if (ev->channel == request.truth_channel) {
        wingman::ground_truth_t truth;
        if (truth.decode(ev->data, 0, ev->datalen) < 0 || !common::validate_message(truth).empty()) {
          ++summary.undecodable;
          continue;
        }
        ++truth_seen;
        if (truth.image_seq < 0) continue;  // a step without a rendered image
        const int64_t seq = truth.image_seq;
        pending.truth[seq] = std::move(truth);
        try_pair(seq);
        expire(seq);
      }
    }
    read.update(read.total(), fmt::format("{} images written", written_here));
    read.finish();
    summary.unmatched += static_cast<int>(pending.images.size());
    if (images_seen > 0 && truth_seen == 0) {
      throw std::runtime_error(fmt::format(
          "{}: {} images on {} but no ground_truth_t on {}: record the simulator's ground truth with the images",
          log_path, images_seen, request.image_channel, request.truth_channel));
    }
    if (images_seen == 0) {
      throw std::runtime_error(
          fmt::format("{}: no image_t on {}: record the camera images (tools/fly.sh --record-images)", log_path,
                      request.image_channel));
    }
    progress << fmt::format("wingman dataset from-log: {}: {} of {} images written", log_path, written_here,
                            images_seen)
             << std::endl;
  }
  training::write_data_yaml((out / "data.yaml").string(), {"drone"},
                            {"written by wingman dataset from-log: simulated flights' frames, the renderer's boxes"});
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace wingman::tools
