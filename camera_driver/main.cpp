// SPDX-License-Identifier: MIT
// wingman-camera-driver: publishes frames from a V4L2 camera or a video file / image folder as image_t.
#include "wingman/camera_driver/camera_driver.hpp"

#include <wingman/common/runtime.hpp>

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

namespace {

using wingman::status_t;
namespace cd = wingman::camera_driver;
namespace common = wingman::common;

/// Longest wait inside one read, milliseconds: the loop checks for SIGINT/SIGTERM at least this often.
constexpr int kReadTimeoutMs = 50;

int run(common::Runtime& rt, const cd::CameraDriverOptions& options) {
  common::StatusTracker& status = rt.status();
  const std::string& channel = options.output.channel;
  status.declare_output(channel);

  cd::CameraDriver driver(options.output, cd::make_source(options, std::make_shared<cd::SystemV4l2Io>(),
                                                          std::make_shared<cd::SystemClock>()));
  driver.open();  // a missing device or unreadable file throws: one line, exit 1
  status.set_state(status_t::STATE_OK, driver.describe());
  rt.publish_heartbeat();

  std::string stop_reason = "signal";
  bool in_error = false;
  while (!rt.stop_requested()) {
    const cd::DriverStep step = driver.step(kReadTimeoutMs);
    if (step.lost > 0) status.source_dropped(channel, step.lost, step.reason);
    if (step.reconnected || (in_error && step.status != cd::ReadStatus::kDisconnected)) {
      status.set_state(status_t::STATE_OK, driver.describe());
      in_error = false;
    }
    switch (step.status) {
      case cd::ReadStatus::kFrame: {
        const auto t0 = std::chrono::steady_clock::now();
        rt.publish(channel, step.image);
        const double publish_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        status.set_last_processed_seq(step.image.seq);
        status.record_latency_ms(step.convert_ms + publish_ms);
        break;
      }
      case cd::ReadStatus::kDisconnected:
        status.set_state(status_t::STATE_ERROR, step.reason);
        status.set_error(step.reason);
        in_error = true;
        break;
      case cd::ReadStatus::kDropped:
      case cd::ReadStatus::kTimeout:
      case cd::ReadStatus::kEnd:
        break;
    }
    rt.heartbeat_if_due();
    if (driver.done()) {
      stop_reason = step.status == cd::ReadStatus::kEnd ? "end of input" : "output.max_frames reached";
      break;
    }
  }
  const auto& s = driver.source().stats();
  spdlog::info("{}: {} frames published, {} dropped, {} lost in sequence gaps, {} reconnects", stop_reason,
               driver.frames_out(), s.dropped + driver.driver_drops(), s.lost_in_gaps, s.reconnects);
  return rt.shutdown(stop_reason);
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"camera_driver", "wingman-camera-driver",
                                 "Captures frames from a V4L2 camera (or plays a video file or image folder) and "
                                 "publishes them as wingman image_t messages"};
  return common::run_process<cd::CameraDriverOptions>(info, argc, argv, run);
}
