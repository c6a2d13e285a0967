// SPDX-License-Identifier: MIT
// FrameSource helpers.
#include "wingman/camera_driver/frame_source.hpp"

namespace wingman::camera_driver {

const char* read_status_name(ReadStatus status) {
  switch (status) {
    case ReadStatus::kFrame:
      return "frame";
    case ReadStatus::kTimeout:
      return "timeout";
    case ReadStatus::kEnd:
      return "end";
    case ReadStatus::kDropped:
      return "dropped";
    case ReadStatus::kDisconnected:
      return "disconnected";
  }
  return "unknown";
}

}  // namespace wingman::camera_driver
