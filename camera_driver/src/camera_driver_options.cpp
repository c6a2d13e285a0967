// SPDX-License-Identifier: MIT
// Validation of the camera driver's options.
#include "wingman/camera_driver/camera_driver_options.hpp"

#include <wingman/common/config.hpp>

#include <cctype>
#include <cmath>

namespace wingman::camera_driver {

std::vector<std::string> OutputOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  bool channel_ok = !channel.empty();
  for (unsigned char c : channel) channel_ok = channel_ok && std::isgraph(c);
  if (!channel_ok) p.push_back(problem("output.channel", channel, "must be a non-empty name without spaces"));
  if (camera_id < 0 || camera_id > 255) p.push_back(problem("output.camera_id", camera_id, "must be in [0, 255]"));
  if (encoding != "raw" && encoding != "mjpeg")
    p.push_back(problem("output.encoding", encoding, "must be raw or mjpeg"));
  if (jpeg_quality < 1 || jpeg_quality > 100)
    p.push_back(problem("output.jpeg_quality", jpeg_quality, "must be in 1..100"));
  if (max_width != 0 && (max_width < 16 || max_width > 8192))
    p.push_back(problem("output.max_width", max_width, "must be 0 (as captured) or in 16..8192"));
  if (encoding == "mjpeg" && decode_mjpeg) {
    p.push_back(problem("output.decode_mjpeg", "true",
                        "contradicts output.encoding = mjpeg (MJPEG camera frames would be decoded, then encoded "
                        "again); choose one"));
  }
  if (!std::isfinite(time_offset_s) || std::abs(time_offset_s) > 1.0)
    p.push_back(problem("output.time_offset_s", time_offset_s, "must be finite, within [-1, 1] s"));
  if (max_frames < 0) {
    p.push_back(problem("output.max_frames", static_cast<double>(max_frames), "must be >= 0 (0 = no limit)"));
  }
  return p;
}

std::vector<std::string> CameraDriverOptions::validate() const {
  std::vector<std::string> p;
  if (source_kind != "v4l2" && source_kind != "file") {
    p.push_back(common::problem("source.kind", source_kind, "must be v4l2 or file"));
  }
  for (auto& s : v4l2.validate()) p.push_back(std::move(s));
  for (auto& s : file.validate(source_kind == "file")) p.push_back(std::move(s));
  for (auto& s : output.validate()) p.push_back(std::move(s));
  for (auto& s : preview.validate()) p.push_back(std::move(s));
  return p;
}

}  // namespace wingman::camera_driver
