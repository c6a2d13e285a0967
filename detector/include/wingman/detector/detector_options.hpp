// SPDX-License-Identifier: MIT
// Options of wingman-detector (config/detector.yaml).
#pragma once

#include "wingman/detector/detection_pipeline.hpp"
#include "wingman/detector/motion_cue.hpp"
#include "wingman/detector/opencl_options.hpp"
#include "wingman/detector/track_windows.hpp"

#include <wingman/common/time_sanity.hpp>

#include <string>
#include <vector>

namespace wingman::detector {

/// Options of the detector process.
struct DetectorOptions {
  std::string input_channel = "IMAGE_CAM0";        ///< image_t input channel
  std::string output_channel = "DETECTIONS_CAM0";  ///< detections_t output channel
  int max_image_width = 8192;                      ///< larger images are dropped and counted, pixels, 1..65536
  int max_image_height = 8192;                     ///< pixels, 1..65536
  /// realtime: when busy, keep only the newest frame (older ones are dropped and counted);
  /// replay: process every frame in order (deterministic; for logs and lockstep replays).
  std::string mode = "realtime";
  /// Darknet .cfg path, or builtin:wingman-small (the shipped model, models/wingman-small.cfg) or
  /// builtin:tiny-yolo-thesis (the thesis network, models/tiny-yolo-thesis.cfg), both built into the binary.
  std::string cfg = "builtin:wingman-small";
  /// Darknet .weights path, or builtin:wingman-small (the shipped trained model, built in; card:
  /// models/wingman-small.md); "" = no model: images are checked and counted, nothing is detected.
  std::string weights = "builtin:wingman-small";
  /// auto: in realtime mode the faster of opencl and cpu here, timed at start-up (a GPU too: the kernels are shaped
  /// for CPUs); in replay mode opencl, not timed (a timed choice can differ from run to run, and the two backends'
  /// boxes differ in the 4th decimal: replays would not repeat); without a usable OpenCL device (no platform, no
  /// device, kernels that fail to build) the CPU backend, with one warning saying why.
  /// opencl: OpenCL or nothing (no usable device: exit 1 with one line). cpu: OpenCV DNN.
  /// The backend that runs, and why, is the heartbeat's detail. auto chooses once, at start-up: a network built
  /// later for another frame size (model.input_size auto) takes the same kind.
  std::string backend = "auto";
  /// Network input size (InputSize::parse): auto (default) keeps the cfg's longer side and fits the other to the
  /// camera's aspect, rounded to a multiple of 32 (640x352 for 1280x720 frames, 640x512 for 640x512 ones; the
  /// network is built at the cfg's size at start-up and again on the first frame that needs another); cfg: the
  /// cfg's [net] size; WxH: that size.
  std::string input_size = "auto";
  DetectorPipelineOptions detection;
  WindowOptions windows;  ///< tracker-driven windows (windows.*)
  MotionOptions motion;   ///< motion-proposed windows (motion.*; the window network of windows.*)
  OpenClOptions opencl;
  /// Time sanity of the images (time.*): an image dated more than max_ahead_s after the newest accepted image, or
  /// not after the previous one, is dropped and counted (never detected, its time never passed on); after
  /// resync_after_s of such images in order the detector re-anchors on them (common/time_sanity.hpp).
  common::TimeSanityOptions time;

  template <class V>
  void visit(V& v) {
    v("input.channel", input_channel, "image_t channel to read camera frames from");
    v("input.max_image_width", max_image_width, "wider images are dropped and counted, pixels");
    v("input.max_image_height", max_image_height, "taller images are dropped and counted, pixels");
    v("input.mode", mode, "realtime (newest frame when busy, drops counted) or replay (every frame, deterministic)");
    v("output.channel", output_channel, "detections_t channel to publish detections on");
    v("model.cfg", cfg, "Darknet .cfg path, or builtin:wingman-small (shipped) or builtin:tiny-yolo-thesis");
    v("model.weights", weights,
      "Darknet .weights path, or builtin:wingman-small (shipped, models/wingman-small.md); \"\" = no model "
      "(images are checked and counted only)");
    v("model.backend", backend,
      "auto (realtime mode: the faster of opencl/cpu here, timed at start-up; replay mode: opencl, not timed, so that "
      "replays repeat; no usable OpenCL device: cpu, with a warning), opencl (no usable OpenCL device: exit 1) or cpu");
    v("model.input_size", input_size,
      "network input: auto (the cfg's longer side, the other fitted to the images' aspect, a multiple of 32), cfg "
      "(the cfg's size) or WxH (multiples of 32)");
    detection.visit(v);
    windows.visit(v);
    motion.visit(v);
    opencl.visit(v);
    time.visit(v);
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::detector
