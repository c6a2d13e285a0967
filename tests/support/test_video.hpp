// SPDX-License-Identifier: MIT
// Test videos for the tests that read clips (library wingman::test_video, which links opencv_videoio).
#pragma once

#include <string>

namespace wingman::testing {

/// Writes an MJPG .avi of `frames` frames, `width` x `height`, with a bright square moving one
/// step per frame over a textured background (OpenCV's built-in AVI writer, no ffmpeg needed).
void write_test_video(const std::string& path, int frames, int width, int height, double fps);

}  // namespace wingman::testing
