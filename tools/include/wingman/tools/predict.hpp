// SPDX-License-Identifier: MIT
// `wingman predict`: the detector (Algorithm 2) on image files, writing YOLO-format labels and drawn images.
#pragma once

#include <wingman/detector/box.hpp>
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
      "builtin:wingman-small";  ///< Darknet .weights path or builtin:wingman-small (the shipped model)
  std::string backend =
      "auto";  ///< inference backend: auto (opencl whenever usable, not timed), opencl or cpu (OpenCV DNN)
  /// Network input size (detector::InputSize::parse): auto fits the cfg's size to each image's aspect; cfg; WxH.
  std::string input_size = "auto";
  std::string out_dir = "predictions";          ///< folder for <stem>.txt (and <stem>.pred.jpg with draw)
  bool draw = false;                            ///< also write each image with its boxes drawn
  detector::DetectorPipelineOptions detection;  ///< p_thresh, o_thresh, subsquare, zoom_in, policy, ...
};

/// One line of a `wingman predict` label file for box `b` (pixels, already clipped to the image) of an image of
/// `image_width` x `image_height` pixels, newline included: `class cx cy w h confidence`, YOLO format (class =
/// b.class_id: 0 drone, 1 airplane, 2 bird, 3 helicopter with a multi-class model; centre and size normalised by
/// the image size; confidence = b.confidence, the score of that class; 6 decimals). Six fields, as training's
/// read_yolo_predictions() reads them: the drone score (b.drone_score) has no field here.
std::string prediction_line(const detector::Box& b, double image_width, double image_height);

/// Runs `wingman predict`: for each image writes `<out_dir>/<stem>.txt` with one prediction_line() per detection
/// of every class, and with `draw` `<out_dir>/<stem>.pred.jpg` (each box labelled with its class name and
/// confidence). Prints one line per image on `out`.
/// Returns 0 when every image was processed, 1 when some could not be read or the model cannot be loaded,
/// 2 on bad options. Errors are lines on `err` ("wingman predict: error: ...").
int run_predict(const PredictOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
