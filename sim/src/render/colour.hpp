// SPDX-License-Identifier: MIT
// Colours from configuration: sRGB triples in 0..1 or 0..255, to linear RGB.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace wingman::sim::detail {

/// "" if `rgb` is three finite numbers, all in 0..1 or all in 0..255; else the rule it breaks.
std::string check_colour(const std::vector<double>& rgb);

/// Appends "key = [values]: rule" to `problems` when check_colour(rgb) fails.
void check_colour_key(const std::string& key, const std::vector<double>& rgb, std::vector<std::string>& problems);

/// The sRGB triple (0..1, or 0..255 when any component exceeds 1) as display values in 0..1.
/// Precondition: check_colour(rgb) is "".
Eigen::Vector3d display_colour(const std::vector<double>& rgb);

/// sRGB display value (0..1) to linear light, per component (IEC 61966-2-1).
double srgb_to_linear(double c);
Eigen::Vector3d srgb_to_linear(const Eigen::Vector3d& c);

/// The linear RGB of a configured sRGB colour.
inline Eigen::Vector3d linear_colour(const std::vector<double>& rgb) { return srgb_to_linear(display_colour(rgb)); }

}  // namespace wingman::sim::detail
