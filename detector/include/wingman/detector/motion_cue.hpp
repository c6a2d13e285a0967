// SPDX-License-Identifier: MIT
// The motion cue (issue 31): where something small moves against the camera-motion-compensated background, a
// full-resolution window for the window network, so that a drone too small for the single pass can still be found.
#pragma once

#include "wingman/detector/box.hpp"
#include "wingman/detector/track_windows.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace wingman::detector {

/// Options of the motion cue (keys `motion.*` of config/detector.yaml).
struct MotionOptions {
  /// Propose full-resolution windows where something small moves against the background (frame differences after
  /// aligning the last three frames); the window network (windows.crop_px, windows.p_thresh) decides what is there.
  bool enabled = false;
  /// The differences are taken on the grey frame resized by this, (0, 1]: 0.25 makes 1280x720 320x180.
  double scale = 0.25;
  /// Each frame is compared with the frames this many and twice this many before it (a slow or far mover must move
  /// more than its own size and a resized pixel in between), 1..30. 10 at 30 Hz: a drone crossing at 3 m/s 40 m away
  /// (1.6 px a frame at 640 px focal length) moves 4 resized pixels.
  int lag_frames = 10;
  /// A pixel moves when its smaller difference (to the frames lag_frames and 2 lag_frames before, aligned) exceeds
  /// this many robust standard deviations (1.4826 MAD) of the frame's differences, > 0.
  double threshold_sigma = 6.0;
  int min_difference = 10;  ///< and at least this many grey levels, 1..255
  /// A blob must also stand out from its 9x9 surroundings in this frame by this many grey levels (where a target has
  /// just been, the background does not), >= 0.
  double min_contrast = 10.0;
  /// Moving blobs larger than this many pixels of the resized frame are not a small target (a cloud edge, a near
  /// object: the single pass sees those), >= 1.
  int max_blob_px = 40;
  /// Nor blobs wider or taller than this many resized pixels (the leading edge of a large mover), >= 1.
  int max_blob_side_px = 8;
  /// A blob counts only when the frame before had one within this distance (a mover repeats; noise and flicker do
  /// not), full-image pixels; 0: every blob counts. >= 0.
  double repeat_radius_px = 32.0;
  int max_windows = 2;  ///< windows per frame at most, the blobs with the largest differences first, >= 1
  /// Consecutive frames must be within this of each other; a larger gap (or another frame size) starts again, s, > 0.
  double max_gap_s = 0.25;
  /// Blobs this close to the resized frame's border are left out (what the alignment shifts in), pixels, >= 0.
  int border_px = 4;
  /// A window's centre's standard deviation for the window gate (windows.gate_sigma), full-image pixels, > 0.
  double sigma_px = 6.0;
  /// The largest image shift between two frames the alignment accepts, as a fraction of the resized frame's
  /// shorter side, (0, 0.5]; a larger one (a fast turn) starts again.
  double max_shift_fraction = 0.1;

  template <class V>
  void visit(V& v) {
    v("motion.enabled", enabled,
      "search at full resolution where something small moves against the aligned background (the window network "
      "decides what it is)");
    v("motion.scale", scale, "frame differences on the grey frame resized by this, (0, 1]");
    v("motion.lag_frames", lag_frames,
      "compare each frame with the frames this many and twice this many before (1..30)");
    v("motion.threshold_sigma", threshold_sigma,
      "a pixel moves when its smaller difference to the frames lag_frames and 2 lag_frames before exceeds this many "
      "robust sigmas");
    v("motion.min_difference", min_difference, "and at least this many grey levels (1..255)");
    v("motion.min_contrast", min_contrast,
      "a blob must also stand out from its 9x9 resized surroundings in this frame by this many grey levels (>= 0)");
    v("motion.max_blob_px", max_blob_px, "moving blobs larger than this many resized pixels are left out (>= 1)");
    v("motion.max_blob_side_px", max_blob_side_px, "and those wider or taller than this many resized pixels (>= 1)");
    v("motion.repeat_radius_px", repeat_radius_px,
      "a blob counts only when the frame before had one this near, full-image pixels (0: every blob)");
    v("motion.max_windows", max_windows, "windows per frame at most, largest difference first (>= 1)");
    v("motion.max_gap_s", max_gap_s, "consecutive frames further apart than this start again, s (> 0)");
    v("motion.border_px", border_px, "blobs this close to the resized frame's border are left out, pixels (>= 0)");
    v("motion.sigma_px", sigma_px, "a motion window's centre sigma for the window gate, full-image pixels (> 0)");
    v("motion.max_shift_fraction", max_shift_fraction,
      "largest alignment shift between frames, fraction of the resized frame's shorter side, (0, 0.5]");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// One moving blob, in full-image pixels.
struct MotionBlob {
  double cx = 0, cy = 0;  ///< centre, pixels (origin at the top-left pixel's corner)
  double w = 0, h = 0;    ///< bounding box, pixels
  int difference = 0;     ///< the blob's largest difference, grey levels
};

/// What the motion cue did since construction.
struct MotionStats {
  int64_t frames = 0;     ///< frames given
  int64_t compared = 0;   ///< of them, frames with the two earlier ones to compare with
  int64_t blobs = 0;      ///< moving blobs found (small, away from the border and from boxes, repeated)
  int64_t windows = 0;    ///< of them, proposed as windows (max_windows per frame)
  int64_t unaligned = 0;  ///< frames ECC could not align to the one before (featureless): the last step was taken
  int64_t restarts = 0;   ///< starts again (a time gap, a new frame size, a shift beyond max_shift_fraction)
};

/// Finds small moving things in a sequence of frames. Each frame's grey image (resized by scale) is aligned to the one
/// before (ECC on both at half that size, a translation: camera rotation between frames at 30 Hz moves a distant
/// background by a near-uniform shift; started from the last step), and the frames lag_frames and 2 lag_frames before
/// are moved onto it by the sum of the steps since, to the nearest pixel. Its difference to each is how far a pixel
/// lies outside the range of that frame's 3x3 neighbourhood (so an edge missed by a pixel, or the place a target has
/// just left, does not count), and a pixel moves when both differences exceed the threshold. Blobs (8-connected) that
/// are small (max_blob_px, max_blob_side_px), stand out from their surroundings in this frame (min_contrast), lie away
/// from the border and from what the shifts brought in, away from the boxes already found, and had a blob near them in
/// the frame before (repeat_radius_px) become windows, largest difference first. Deterministic: the same frames with
/// the same times give the same windows. Not thread-safe: one sequence, in order.
class MotionCue {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit MotionCue(MotionOptions options);

  /// The moving blobs of frame `bgr` (8-bit, 1 or 3 channels) taken at `utime` (microseconds, increasing), leaving out
  /// those whose centre lies in a box of `found` grown by half its size on each side; at most max_windows, largest
  /// difference first. Empty for the first 2 lag_frames + 1 frames of a sequence.
  std::vector<MotionBlob> find(const cv::Mat& bgr, int64_t utime, const std::vector<Box>& found);

  /// find()'s blobs as windows for WindowDetector (sigma_px from the options).
  std::vector<Window> windows(const cv::Mat& bgr, int64_t utime, const std::vector<Box>& found);

  const MotionStats& stats() const { return stats_; }
  const MotionOptions& options() const { return options_; }

 private:
  struct Frame {
    cv::Mat grey;  ///< CV_32F, resized
    cv::Mat half;  ///< grey at half its size (the alignment's)
    int64_t utime = 0;
    cv::Point2d step;  ///< the shift that moved the frame before onto this one, resized pixels
  };
  void restart();
  /// The shift that moves `previous` onto `current` (resized pixels), found by ECC (a translation) from `guess`, then
  /// from no shift; nullopt when neither converges.
  std::optional<cv::Point2d> align(const cv::Mat& previous, const cv::Mat& current, cv::Point2d guess) const;

  MotionOptions options_;
  std::deque<Frame> history_;  ///< the 2 lag_frames frames before
  cv::Size full_size_;
  std::vector<MotionBlob> previous_blobs_;  ///< the last compared frame's blobs (before the repeat rule)
  cv::Point2d last_step_;  ///< the shift between the last two frames, resized pixels (the next alignment's start)
  MotionStats stats_;
};

}  // namespace wingman::detector
