// SPDX-License-Identifier: MIT
// The network input size: the cfg's, a fixed one, or fitted to the aspect of the images (model.input_size).
#pragma once

#include <opencv2/core.hpp>

#include <optional>
#include <string>

namespace wingman::detector {

/// How the network's input size is chosen (`model.input_size`, `--input-size`).
/// The weights do not depend on it (every layer is convolutional); the cost grows with its area.
struct InputSize {
  enum class Mode {
    kAuto,   ///< "auto": fit_input_size() of the cfg's size to each image's detection region
    kCfg,    ///< "cfg": the cfg's [net] width x height, whatever the images
    kFixed,  ///< "WxH": this size, whatever the images
  };
  Mode mode = Mode::kAuto;
  cv::Size fixed;  ///< kFixed only: width x height, pixels, each a multiple of 32, >= 32

  /// "auto", "cfg" or "WxH" (e.g. "640x512"; each side a multiple of 32, >= 32, <= 4096). std::nullopt, with
  /// `error` (if not null) saying what was expected, otherwise.
  static std::optional<InputSize> parse(const std::string& text, std::string* error = nullptr);
  /// "auto", "cfg" or "WxH".
  std::string to_string() const;
};

/// auto's rule. The network input keeps `cfg_net`'s longer side along `region`'s longer side; the other side
/// follows the region's aspect, rounded to the nearest multiple of 32 (at least 32). A 640x352 cfg gives
/// 640x352 for 1280x720 images, 640x512 for 640x512 ones, 640x640 for a square region and 352x640 for
/// 720x1280. Stretching an image to another aspect instead squeezes one axis: a 640x512 frame at 640x352
/// keeps 69 % of its rows, and small drones lose them (models/wingman-small.md measures it).
/// Preconditions: both sizes positive (std::invalid_argument otherwise).
cv::Size fit_input_size(cv::Size cfg_net, cv::Size region);

}  // namespace wingman::detector
