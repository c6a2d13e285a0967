// SPDX-License-Identifier: MIT
// Checks of decoded messages beyond what LCM's decoder guarantees; each names the field and the rule.
#pragma once

#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <string>

namespace wingman::common {

/// Limits applied to every image (reject before use; decoding already bounded the allocation by
/// the datagram size).
struct ImageLimits {
  int max_width = 8192;   ///< pixels
  int max_height = 8192;  ///< pixels
};

/// Each returns "" when the message is usable, else one line naming the field, its value and the rule.
std::string validate_message(const wingman::image_t& msg, const ImageLimits& limits = {});
std::string validate_message(const wingman::detections_t& msg);
std::string validate_message(const wingman::own_pose_t& msg);
std::string validate_message(const wingman::targets_t& msg);
std::string validate_message(const wingman::setpoint_t& msg);
std::string validate_message(const wingman::status_t& msg);
std::string validate_message(const wingman::ground_truth_t& msg);
/// Also: utime_predicted >= utime, image size > 0, every window's numbers finite, w, h, range_m > 0, sigma_px >= 0,
/// confidence in [0, 1].
std::string validate_message(const wingman::track_windows_t& msg);

/// Bytes per pixel of a raw image_t pixel format (GRAY8 1, BGR8 3, YUYV 2), 0 for MJPEG or unknown.
int bytes_per_pixel(int8_t pixel_format);
/// "GRAY8", "BGR8", "YUYV", "MJPEG" or "unknown(N)".
std::string pixel_format_name(int8_t pixel_format);

}  // namespace wingman::common
