// SPDX-License-Identifier: MIT
// `wingman make-video`: writes a synthetic test clip (no external data needed).
#pragma once

#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman make-video`.
struct MakeVideoOptions {
  std::string output;  ///< .avi path (MJPG, OpenCV's built-in writer: no ffmpeg needed)
  int frames = 90;     ///< number of frames
  int width = 640;     ///< pixels
  int height = 480;    ///< pixels
  double fps = 30.0;   ///< frames per second

  /// Every problem, one line each named by `wingman make-video`'s key (output.file, video.*); empty when valid.
  std::vector<std::string> validate() const;
};

/// Writes a clip of a sky-like gradient with a dark quadcopter-like shape moving across it, so the
/// frames differ from each other and show something. Deterministic: the same options give the same
/// frames. Throws std::runtime_error naming the file if it cannot be written.
void make_video(const MakeVideoOptions& options);

}  // namespace wingman::tools
