// SPDX-License-Identifier: MIT
// Colours from configuration: sRGB triples in 0..1 or 0..255, to linear RGB.
#include "colour.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace wingman::sim::detail {

std::string check_colour(const std::vector<double>& rgb) {
  if (rgb.size() != 3) return "expected 3 numbers [r, g, b]";
  for (double c : rgb) {
    if (!std::isfinite(c) || c < 0.0 || c > 255.0) return "expected [r, g, b] in 0..1 or 0..255";
  }
  return "";
}

void check_colour_key(const std::string& key, const std::vector<double>& rgb, std::vector<std::string>& problems) {
  const std::string rule = check_colour(rgb);
  if (!rule.empty()) problems.push_back(common::problem(key, fmt::format("[{}]", fmt::join(rgb, ", ")), rule));
}

Eigen::Vector3d display_colour(const std::vector<double>& rgb) {
  const bool bytes = std::any_of(rgb.begin(), rgb.end(), [](double c) { return c > 1.0; });
  const double scale = bytes ? 1.0 / 255.0 : 1.0;
  return Eigen::Vector3d(rgb[0], rgb[1], rgb[2]) * scale;
}

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

Eigen::Vector3d srgb_to_linear(const Eigen::Vector3d& c) {
  return {srgb_to_linear(c.x()), srgb_to_linear(c.y()), srgb_to_linear(c.z())};
}

}  // namespace wingman::sim::detail
