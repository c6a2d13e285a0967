// SPDX-License-Identifier: MIT
// `wingman predict`: the detector (Algorithm 2) on image files, writing YOLO-format labels and drawn images.
#pragma once

#include <wingman/detector/detection_pipeline.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman predict`.
struct PredictOptions {
  std::vector<std::string> inputs;            ///< image files and/or folders (their images, not recursive)
  std::string cfg = "builtin:wingman-small";  ///< Darknet .cfg path or builtin:<name> (detector::load_model)
  std::string weights =
      "builtin:wingman-small";   ///< Darknet .weights path or builtin:wingman-small (the shipped model)
  std::string backend = "auto";  ///< inference backend: auto, opencl or cpu (OpenCV DNN)
  /// Network input size (detector::InputSize::parse): auto fits the cfg's size to each image's aspect; cfg; WxH.
  std::string input_size = "auto";
  std::string out_dir = "predictions";          ///< folder for <stem>.txt (and <stem>.pred.jpg with draw)
  bool draw = false;                            ///< also write each image with its boxes drawn
  detector::DetectorPipelineOptions detection;  ///< p_thresh, o_thresh, subsquare, zoom_in, policy, ...
};

/// Runs `wingman predict`: for each image writes `<out_dir>/<stem>.txt` with one line per detection,
/// `0 cx cy w h confidence` (YOLO format: class 0, centre and size normalised by the image size), and with
/// `draw` `<out_dir>/<stem>.pred.jpg`. Prints one line per image on `out`.
/// Returns 0 when every image was processed, 1 when some could not be read or the model cannot be loaded,
/// 2 on bad options. Errors are lines on `err` ("wingman predict: error: ...").
int run_predict(const PredictOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
