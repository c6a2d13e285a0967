// SPDX-License-Identifier: MIT
// model.input_size: parsing and auto's fitting rule.
#include "wingman/detector/input_size.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace wingman::detector {

namespace {

constexpr int kStep = 32;       // network input sides are multiples of this
constexpr int kMaxSide = 4096;  // larger is a typo, not a network input

/// A whole decimal number in 1..kMaxSide, or -1.
int parse_side(const std::string& s) {
  if (s.empty() || s.size() > 5 || s.find_first_not_of("0123456789") != std::string::npos) return -1;
  const int v = std::atoi(s.c_str());
  return v >= 1 && v <= kMaxSide ? v : -1;
}

}  // namespace

std::optional<InputSize> InputSize::parse(const std::string& text, std::string* error) {
  if (text == "auto") return InputSize{Mode::kAuto, {}};
  if (text == "cfg") return InputSize{Mode::kCfg, {}};
  const size_t x = text.find('x');
  if (x != std::string::npos) {
    const int w = parse_side(text.substr(0, x));
    const int h = parse_side(text.substr(x + 1));
    if (w >= kStep && h >= kStep && w % kStep == 0 && h % kStep == 0) return InputSize{Mode::kFixed, {w, h}};
  }
  if (error)
    *error = fmt::format("'{}': expected auto, cfg or WxH (e.g. 640x512; each side a multiple of {}, {}..{})", text,
                         kStep, kStep, kMaxSide);
  return std::nullopt;
}

std::string InputSize::to_string() const {
  switch (mode) {
    case Mode::kAuto:
      return "auto";
    case Mode::kCfg:
      return "cfg";
    case Mode::kFixed:
      break;
  }
  return fmt::format("{}x{}", fixed.width, fixed.height);
}

cv::Size fit_input_size(cv::Size cfg_net, cv::Size region) {
  if (cfg_net.width <= 0 || cfg_net.height <= 0 || region.width <= 0 || region.height <= 0)
    throw std::invalid_argument(fmt::format("fit_input_size: network {}x{}, region {}x{}: both must be positive",
                                            cfg_net.width, cfg_net.height, region.width, region.height));
  const int long_side = std::max(cfg_net.width, cfg_net.height);
  const bool landscape = region.width >= region.height;
  const double ratio =
      landscape ? static_cast<double>(region.height) / region.width : static_cast<double>(region.width) / region.height;
  const int short_side = std::max(kStep, static_cast<int>(std::lround(long_side * ratio / kStep)) * kStep);
  return landscape ? cv::Size(long_side, short_side) : cv::Size(short_side, long_side);
}

}  // namespace wingman::detector
