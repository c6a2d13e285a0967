// SPDX-License-Identifier: MIT
// Tracker-driven windows (issue 31): full-resolution crops where wingman-localizer's tracks will be.
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/box.hpp"
#include "wingman/detector/darknet_model.hpp"
#include "wingman/detector/detection_pipeline.hpp"

#include <opencv2/core.hpp>
#include <wingman/track_windows_t.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace wingman::detector {

/// Options of the tracker-driven windows (keys `windows.*` of config/detector.yaml; the localizer publishes them with
/// its windows.publish).
struct WindowOptions {
  /// Read the localizer's track_windows_t and detect at full resolution where its tracks will be, when the single pass
  /// would see them too small.
  bool enabled = false;
  std::string channel = "WINDOWS_CAM0";  ///< track_windows_t input channel
  /// Side of the square full-resolution crop, pixels: also the window network's input (no resize). A multiple of 32,
  /// 32..1024. 256: a fifth of a 640x352 single pass's work per window.
  int crop_px = 256;
  int max_per_frame = 2;  ///< crops per frame at most (windows sharing a crop count once), >= 1
  /// A window is searched when the predicted box would be smaller than this in the single pass's network pixels
  /// (sqrt(w h) x network width / image width), pixels, > 0. 14: the default quad beyond about 13 m at 1280x720 and
  /// 90 degrees (the shipped model's single pass finds it to 17.5 m, where its box is about 10 network pixels); nearer,
  /// the single pass's boxes are what the box relation was measured on.
  double max_net_px = 14.0;
  /// Confidence threshold of the boxes found in a window, 0..1. (A window is where a track predicts a drone.)
  double p_thresh = 0.2;
  /// A window's box is taken when its centre lies within gate_sigma x the window's sigma_px plus half the predicted
  /// box's larger side (at least one pixel) of the predicted centre, in each axis. > 0.
  double gate_sigma = 3.0;
  /// Windows predicted for more than this before or after the image's exposure are not used, s, > 0.
  double max_age_s = 0.5;
  bool confirmed_only = false;  ///< only the windows of confirmed tracks (not tentative ones)

  template <class V>
  void visit(V& v) {
    v("windows.enabled", enabled,
      "detect at full resolution where the localizer's tracks will be (track_windows_t) when the single pass would "
      "see them too small");
    v("windows.channel", channel, "track_windows_t input channel (the localizer's windows.channel)");
    v("windows.crop_px", crop_px,
      "side of each square full-resolution crop and its network input, pixels (32..1024, "
      "multiple of 32)");
    v("windows.max_per_frame", max_per_frame, "crops per frame at most (>= 1)");
    v("windows.max_net_px", max_net_px,
      "search a window when its box would be below this many single-pass network pixels (sqrt(w h)), > 0");
    v("windows.p_thresh", p_thresh, "confidence threshold inside a window (0..1)");
    v("windows.gate_sigma", gate_sigma,
      "a window's box must lie within this many sigma_px (plus half the predicted box) of the predicted centre");
    v("windows.max_age_s", max_age_s, "windows predicted further than this from the image's exposure are unused, s");
    v("windows.confirmed_only", confirmed_only, "only confirmed tracks' windows");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// One window moved to an image's exposure, in full-image pixels (origin at the top-left pixel's corner).
struct Window {
  double cx = 0, cy = 0;  ///< predicted box centre, pixels
  double w = 0, h = 0;    ///< predicted box size, pixels
  double sigma_px = 0;    ///< the centre's standard deviation, pixels
  bool confirmed = false;
  int32_t track_id = 0;
};

/// The windows of `m` to search in an image of `image` size taken at `image_utime` by camera `camera_id`:
/// none when the camera, the image size or the time does not match (|image_utime - m.utime_predicted| >
/// max_age_s); each window's centre moved by its image velocity to image_utime; only windows whose box lies at least
/// partly in the image, whose predicted size sqrt(w h) x `net_px_per_image_px` is below max_net_px, and (with
/// confirmed_only) of confirmed tracks; in the message's order (confirmed first).
std::vector<Window> windows_to_search(const wingman::track_windows_t& m, int64_t image_utime, cv::Size image,
                                      int32_t camera_id, double net_px_per_image_px, const WindowOptions& options);

/// Crops of crop_px x crop_px (the image's size where it is smaller) for `windows`, in order: a window whose
/// gate (centre +- gate_sigma sigma_px + half its box) lies inside an earlier crop shares it; otherwise a new crop
/// centred on it, clamped inside the image, while fewer than max_per_frame. `crop_of_window[i]` is window i's crop,
/// or -1 when the budget left it out.
std::vector<cv::Rect> place_window_crops(const std::vector<Window>& windows, cv::Size image,
                                         const WindowOptions& options, std::vector<int>& crop_of_window);

/// What the windows did in one image.
struct WindowStats {
  int windows = 0;  ///< windows searched (with a crop)
  int crops = 0;    ///< crops run through the network
  int found = 0;    ///< windows whose crop gave a box in their gate
};

/// The single pass's boxes and the windows' boxes together: for each searched window (in order), the most confident
/// drone box (class 0) of its crop whose centre lies in its gate, in full-image pixels, of pass kWindow (a
/// full-resolution re-detection); it replaces every first-pass box of the same drone: one it overlaps at IoU >
/// o_thresh, whose centre lies in it or holds its centre, or whose centre lies in the window's gate (the single pass's
/// box of a far drone is often twice its size and offset, touching the drone's box at IoU near 0: measured in
/// tools/experiment.sh fly_away at 20-25 m). Then non-max suppression (o_thresh), most confident first, at most
/// `max_detections` (with policy most_confident: 1). `crop_boxes[c]` are crop c's boxes in crop pixels.
std::vector<Box> merge_window_boxes(std::vector<Box> first_pass, const std::vector<Window>& windows,
                                    const std::vector<cv::Rect>& crops, const std::vector<int>& crop_of_window,
                                    const std::vector<std::vector<Box>>& crop_boxes,
                                    const DetectorPipelineOptions& pipeline, const WindowOptions& options,
                                    WindowStats* stats = nullptr);

/// The window network: Algorithm 2's steps 2-3 on crop_px x crop_px crops at full resolution (windows.p_thresh;
/// no zoom-in, mirror or coarse pass), a frame's crops in one batch (DetectionPipeline::detect_regions(), up to the
/// backend's max_batch), built once through `make_backend` with the model at that input size.
class WindowDetector {
 public:
  using BackendFactory = std::function<std::unique_ptr<InferenceBackend>(const DarknetModel& model)>;
  /// Throws std::invalid_argument for invalid options and what the backend factory throws.
  WindowDetector(WindowOptions options, const DetectorPipelineOptions& pipeline, const DarknetModel& model,
                 const BackendFactory& make_backend);

  /// `first_pass`: the single pass's boxes of `bgr_image` (full-image pixels); `windows`: windows_to_search().
  /// Returns merge_window_boxes() of the crops place_window_crops() gives.
  std::vector<Box> detect(const cv::Mat& bgr_image, std::vector<Box> first_pass, const std::vector<Window>& windows,
                          WindowStats* stats = nullptr);
  /// The same with another crop budget (max_per_frame) and gate (gate_sigma) than the options' (the motion cue's
  /// windows); crop_px must be the options' (the network's input; else std::logic_error), p_thresh is the network's.
  std::vector<Box> detect(const cv::Mat& bgr_image, std::vector<Box> first_pass, const std::vector<Window>& windows,
                          const WindowOptions& options, WindowStats* stats);
  const WindowOptions& options() const { return options_; }

 private:
  WindowOptions options_;
  DetectorPipelineOptions pipeline_options_;  ///< the single pass's (NMS, policy, max_detections of the merge)
  std::unique_ptr<DetectionPipeline> pipeline_;
  std::vector<int> crop_of_window_;
};

}  // namespace wingman::detector
