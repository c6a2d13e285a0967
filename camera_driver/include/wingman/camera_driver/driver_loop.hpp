// SPDX-License-Identifier: MIT
// The loop of wingman-camera-driver: CameraDriver steps published through the Runtime, with the heartbeat's state.
#pragma once

#include "wingman/camera_driver/camera_driver.hpp"
#include "wingman/camera_driver/preview.hpp"

#include <wingman/common/runtime.hpp>

#include <string>

namespace wingman::camera_driver {

/// Longest wait inside one read, milliseconds: the loop checks for SIGINT/SIGTERM at least this often.
constexpr int kDriverReadTimeoutMs = 50;

/// Publishes `driver`'s frames on `channel` until a stop is requested, the source ends or output.max_frames frames
/// were produced; returns rt.shutdown()'s code. `driver` must be open.
///
/// Heartbeat: state OK with the source's description while frames come; ERROR with the source's one-line reason
/// (e.g. "device /dev/video0 ... ENODEV, reconnecting") from the moment the camera is lost until it is back; then OK
/// again, the detail counting disconnects and reconnects. A heartbeat is published at once on each of these changes,
/// not only at the status period. Frames lost in gaps or dropped are counted as source drops; nothing is published
/// while the camera is gone. After a frame, its preview (PreviewMaker, when due) goes to preview.channel_for(channel).
int run_driver_loop(common::Runtime& rt, CameraDriver& driver, const std::string& channel,
                    const PreviewOptions& preview = PreviewOptions{});

}  // namespace wingman::camera_driver
