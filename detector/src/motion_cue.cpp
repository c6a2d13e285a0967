// SPDX-License-Identifier: MIT
#include "wingman/detector/motion_cue.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace wingman::detector {

namespace {

/// The grey frame, resized by `scale` (area averaging), as CV_32F.
cv::Mat resized_grey(const cv::Mat& image, double scale) {
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 1) {
    grey = image;
  } else {
    throw std::invalid_argument(fmt::format("motion cue: {} channels: expected 1 or 3", image.channels()));
  }
  const cv::Size size(std::max(1, static_cast<int>(std::lround(grey.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(grey.rows * scale))));
  cv::Mat small;
  cv::resize(grey, small, size, 0, 0, cv::INTER_AREA);
  cv::Mat f;
  small.convertTo(f, CV_32F);
  return f;
}

/// How far `current` lies outside the range of `previous` (moved by `shift`) in each pixel's 3x3 neighbourhood:
/// max(current - max3x3, min3x3 - current, 0). An edge that the alignment misses by up to a pixel stays inside the
/// range (no difference), and so does the place a small target has just left (its neighbourhood held the background
/// too); where it now is, it differs from all of it.
cv::Mat aligned_difference(const cv::Mat& current, const cv::Mat& previous, const cv::Point2d& shift) {
  // Moved by the whole pixels nearest the shift, not interpolated: the neighbourhood then holds the samples on both
  // sides of each pixel's true place (interpolating would flatten a bright or dark peak, which would then "move").
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, std::round(shift.x), 0, 1, std::round(shift.y));
  cv::Mat moved;
  cv::warpAffine(previous, moved, m, current.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  cv::Mat hi, lo;
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::dilate(moved, hi, k, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  cv::erode(moved, lo, k, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  cv::Mat above = current - hi, below = lo - current;
  cv::Mat d = cv::max(above, below);
  return cv::max(d, 0.0);
}

/// The median and the median absolute deviation of an 8-bit image, from its histogram.
std::pair<int, int> median_and_mad(const cv::Mat& u8) {
  std::array<int64_t, 256> hist{};
  for (int r = 0; r < u8.rows; ++r) {
    const uint8_t* p = u8.ptr<uint8_t>(r);
    for (int c = 0; c < u8.cols; ++c) ++hist[p[c]];
  }
  const int64_t half = (static_cast<int64_t>(u8.total()) + 1) / 2;
  const auto median_of = [half](const std::array<int64_t, 256>& h) {
    int64_t seen = 0;
    for (int v = 0; v < 256; ++v) {
      seen += h[v];
      if (seen >= half) return v;
    }
    return 255;
  };
  const int median = median_of(hist);
  std::array<int64_t, 256> dev{};
  for (int v = 0; v < 256; ++v) dev[std::abs(v - median)] += hist[v];
  return {median, median_of(dev)};
}

}  // namespace

std::vector<std::string> MotionOptions::validate() const {
  std::vector<std::string> e;
  if (!(scale > 0.0 && scale <= 1.0)) e.push_back(fmt::format("motion.scale = {}: must be in (0, 1]", scale));
  if (!(threshold_sigma > 0.0) || !std::isfinite(threshold_sigma))
    e.push_back(fmt::format("motion.threshold_sigma = {}: must be finite and > 0", threshold_sigma));
  if (min_difference < 1 || min_difference > 255)
    e.push_back(fmt::format("motion.min_difference = {}: must be 1..255", min_difference));
  if (!(min_contrast >= 0.0) || !std::isfinite(min_contrast))
    e.push_back(fmt::format("motion.min_contrast = {}: must be finite and >= 0", min_contrast));
  if (max_blob_px < 1) e.push_back(fmt::format("motion.max_blob_px = {}: must be >= 1", max_blob_px));
  if (max_blob_side_px < 1) e.push_back(fmt::format("motion.max_blob_side_px = {}: must be >= 1", max_blob_side_px));
  if (lag_frames < 1 || lag_frames > 30) e.push_back(fmt::format("motion.lag_frames = {}: must be 1..30", lag_frames));
  if (max_windows < 1) e.push_back(fmt::format("motion.max_windows = {}: must be >= 1", max_windows));
  if (!(max_gap_s > 0.0) || !std::isfinite(max_gap_s))
    e.push_back(fmt::format("motion.max_gap_s = {}: must be finite and > 0", max_gap_s));
  if (!(repeat_radius_px >= 0.0) || !std::isfinite(repeat_radius_px))
    e.push_back(fmt::format("motion.repeat_radius_px = {}: must be finite and >= 0", repeat_radius_px));
  if (border_px < 0) e.push_back(fmt::format("motion.border_px = {}: must be >= 0", border_px));
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px))
    e.push_back(fmt::format("motion.sigma_px = {}: must be finite and > 0", sigma_px));
  if (!(max_shift_fraction > 0.0 && max_shift_fraction <= 0.5))
    e.push_back(fmt::format("motion.max_shift_fraction = {}: must be in (0, 0.5]", max_shift_fraction));
  return e;
}

MotionCue::MotionCue(MotionOptions options) : options_(std::move(options)) {
  if (const auto bad = options_.validate(); !bad.empty()) {
    std::string all;
    for (const auto& s : bad) all += (all.empty() ? "" : "; ") + s;
    throw std::invalid_argument(all);
  }
}

void MotionCue::restart() {
  if (!history_.empty()) ++stats_.restarts;
  history_.clear();
  previous_blobs_.clear();
  last_step_ = {};
}

std::optional<cv::Point2d> MotionCue::align(const cv::Mat& previous, const cv::Mat& current, cv::Point2d guess) const {
  // ECC finds t with previous(x + t) ~ current(x); `previous` moved by -t lies on `current`.
  for (const cv::Point2d start : {guess, cv::Point2d{}}) {
    cv::Mat warp = (cv::Mat_<float>(2, 3) << 1, 0, -start.x, 0, 1, -start.y);
    try {
      cv::findTransformECC(current, previous, warp, cv::MOTION_TRANSLATION,
                           cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 20, 1e-2), cv::noArray(),
                           5);
    } catch (const cv::Exception&) {
      continue;  // did not converge (a featureless frame, a jump): from zero, then give up
    }
    const cv::Point2d shift(-warp.at<float>(0, 2), -warp.at<float>(1, 2));
    if (std::isfinite(shift.x) && std::isfinite(shift.y)) return shift;
  }
  return std::nullopt;
}

std::vector<MotionBlob> MotionCue::find(const cv::Mat& bgr, int64_t utime, const std::vector<Box>& found) {
  ++stats_.frames;
  if (bgr.empty() || bgr.depth() != CV_8U) throw std::invalid_argument("motion cue: expected an 8-bit image");
  if (bgr.size() != full_size_ ||
      (!history_.empty() && (utime <= history_.back().utime ||
                             static_cast<double>(utime - history_.back().utime) * 1e-6 > options_.max_gap_s))) {
    restart();
    full_size_ = bgr.size();
  }
  Frame now{resized_grey(bgr, options_.scale), {}, utime, {}};
  cv::pyrDown(now.grey, now.half);
  // Each frame aligned to the one before (a small shift: ECC from the last one); a failed or too large step starts
  // again from this frame.
  const double max_step = options_.max_shift_fraction * std::min(now.grey.cols, now.grey.rows);
  if (!history_.empty()) {
    // On the half-size frames (a quarter of the work; the step is rounded to whole pixels of the full-size ones).
    std::optional<cv::Point2d> step = align(history_.back().half, now.half, last_step_ * 0.5);
    if (step) {
      *step *= 2.0;
    } else {
      // Nothing to align on (a clear sky): the last step stands; where nothing is textured, no shift makes a
      // difference.
      step = last_step_;
      ++stats_.unaligned;
    }
    if (std::hypot(step->x, step->y) > max_step) {
      restart();
    } else {
      now.step = *step;
      last_step_ = *step;
    }
  }

  std::vector<MotionBlob> blobs;
  const size_t lag = static_cast<size_t>(options_.lag_frames);
  if (history_.size() == 2 * lag) {
    ++stats_.compared;
    // The frames lag and 2 lag before moved onto this one by the sum of the steps since.
    cv::Point2d far_shift = now.step, near_shift = now.step;
    for (size_t i = 1; i < history_.size(); ++i) {
      far_shift += history_[i].step;
      if (i > lag) near_shift += history_[i].step;
    }
    std::array<cv::Mat, 2> diffs = {aligned_difference(now.grey, history_[lag].grey, near_shift),
                                    aligned_difference(now.grey, history_[0].grey, far_shift)};
    // Where both earlier frames saw the scene (what the shifts bring in at the edges was not in them).
    const auto lo_edge = [](double a, double b) { return static_cast<int>(std::ceil(std::max({0.0, a, b}))); };
    const auto hi_edge = [](double a, double b) { return static_cast<int>(std::floor(std::min({0.0, a, b}))); };
    const cv::Rect seen(cv::Point(lo_edge(near_shift.x, far_shift.x), lo_edge(near_shift.y, far_shift.y)),
                        cv::Point(now.grey.cols + hi_edge(near_shift.x, far_shift.x),
                                  now.grey.rows + hi_edge(near_shift.y, far_shift.y)));
    const bool aligned = seen.width > 0 && seen.height > 0;
    if (!aligned) {
      restart();
    } else {
      cv::Mat both;
      cv::min(diffs[0], diffs[1], both);
      cv::Mat u8;
      both.convertTo(u8, CV_8U);  // saturates at 255
      const auto [median, mad] = median_and_mad(u8);
      const double threshold =
          std::max<double>(options_.min_difference, median + options_.threshold_sigma * 1.4826 * std::max(mad, 1));
      cv::Mat mask;
      cv::threshold(u8, mask, threshold, 255, cv::THRESH_BINARY);
      // A small target stands out from its surroundings in this frame too (where it has just been does not).
      cv::Mat local, contrast;
      cv::blur(now.grey, local, cv::Size(9, 9), cv::Point(-1, -1), cv::BORDER_REPLICATE);
      cv::absdiff(now.grey, local, contrast);
      cv::Mat labels, stats, centroids;
      const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
      const double to_full_x = static_cast<double>(full_size_.width) / now.grey.cols;
      const double to_full_y = static_cast<double>(full_size_.height) / now.grey.rows;
      for (int l = 1; l < n; ++l) {
        const int x = stats.at<int>(l, cv::CC_STAT_LEFT), y = stats.at<int>(l, cv::CC_STAT_TOP);
        const int w = stats.at<int>(l, cv::CC_STAT_WIDTH), h = stats.at<int>(l, cv::CC_STAT_HEIGHT);
        if (stats.at<int>(l, cv::CC_STAT_AREA) > options_.max_blob_px || std::max(w, h) > options_.max_blob_side_px)
          continue;
        // Away from the frame's border and from what the shifts brought in (plus the neighbourhood's pixel).
        const int b = options_.border_px + 1;
        if (x < seen.x + b || y < seen.y + b || x + w > seen.br().x - b || y + h > seen.br().y - b) continue;
        MotionBlob blob;
        blob.cx = (x + 0.5 * w) * to_full_x;
        blob.cy = (y + 0.5 * h) * to_full_y;
        blob.w = w * to_full_x;
        blob.h = h * to_full_y;
        const bool near_a_box = std::any_of(found.begin(), found.end(), [&](const Box& f) {
          return std::abs(blob.cx - f.cx) <= f.w && std::abs(blob.cy - f.cy) <= f.h;
        });
        if (near_a_box) continue;
        const cv::Rect r(x, y, w, h);
        const cv::Mat in_blob = labels(r) == l;
        double max_value = 0.0, max_contrast = 0.0;
        cv::minMaxLoc(u8(r), nullptr, &max_value, nullptr, nullptr, in_blob);
        cv::minMaxLoc(contrast(r), nullptr, &max_contrast, nullptr, nullptr, in_blob);
        if (max_contrast < options_.min_contrast) continue;
        blob.difference = static_cast<int>(max_value);
        blobs.push_back(blob);
      }
      // A blob counts when the frame before had one near it too (noise and flicker do not repeat).
      std::vector<MotionBlob> all = blobs;
      if (options_.repeat_radius_px > 0.0) {
        const double r = options_.repeat_radius_px;
        blobs.erase(std::remove_if(blobs.begin(), blobs.end(),
                                   [&](const MotionBlob& b) {
                                     return std::none_of(previous_blobs_.begin(), previous_blobs_.end(),
                                                         [&](const MotionBlob& p) {
                                                           return std::hypot(b.cx - p.cx, b.cy - p.cy) <= r;
                                                         });
                                   }),
                    blobs.end());
      }
      previous_blobs_ = std::move(all);
      stats_.blobs += static_cast<int64_t>(blobs.size());
      // Largest difference first; ties by position (deterministic).
      std::sort(blobs.begin(), blobs.end(), [](const MotionBlob& a, const MotionBlob& b) {
        if (a.difference != b.difference) return a.difference > b.difference;
        if (a.cy != b.cy) return a.cy < b.cy;
        return a.cx < b.cx;
      });
      if (blobs.size() > static_cast<size_t>(options_.max_windows)) blobs.resize(options_.max_windows);
      stats_.windows += static_cast<int64_t>(blobs.size());
    }
  }
  history_.push_back(std::move(now));
  if (history_.size() > 2 * lag) history_.pop_front();
  return blobs;
}

std::vector<Window> MotionCue::windows(const cv::Mat& bgr, int64_t utime, const std::vector<Box>& found) {
  std::vector<Window> out;
  for (const MotionBlob& b : find(bgr, utime, found)) {
    Window w;
    w.cx = b.cx;
    w.cy = b.cy;
    w.w = b.w;
    w.h = b.h;
    w.sigma_px = options_.sigma_px;
    out.push_back(w);
  }
  return out;
}

}  // namespace wingman::detector
