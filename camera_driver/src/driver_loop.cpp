// SPDX-License-Identifier: MIT
// The camera driver's process loop (see driver_loop.hpp).
#include "wingman/camera_driver/driver_loop.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>

namespace wingman::camera_driver {

int run_driver_loop(common::Runtime& rt, CameraDriver& driver, const std::string& channel,
                    const PreviewOptions& preview_options) {
  common::StatusTracker& status = rt.status();
  status.declare_output(channel);
  PreviewMaker preview(preview_options);
  const std::string preview_channel = preview_options.channel_for(channel);
  if (preview_options.enabled) status.declare_output(preview_channel);
  std::string stop_reason = "signal";
  bool in_error = false;
  if (const std::string waiting = driver.source().waiting_reason(); !waiting.empty()) {
    status.set_state(status_t::STATE_ERROR, waiting);  // the device was not there at start: waiting for it
    status.set_error(waiting);
    in_error = true;
  } else {
    status.set_state(status_t::STATE_OK, driver.describe());
  }
  rt.publish_heartbeat();

  while (!rt.stop_requested()) {
    const DriverStep step = driver.step(kDriverReadTimeoutMs);
    if (step.lost > 0) status.source_dropped(channel, step.lost, step.reason);
    if ((in_error || step.reconnected) && step.status != ReadStatus::kDisconnected) {
      const SourceStats& s = driver.source().stats();
      if (s.disconnects == 0) {  // the device that was missing at start is there
        status.set_state(status_t::STATE_OK, driver.describe());
        spdlog::info("camera found: {}", driver.describe());
      } else {
        status.set_state(status_t::STATE_OK, fmt::format("{} (back after {} disconnect(s), {} reconnect(s))",
                                                         driver.describe(), s.disconnects, s.reconnects));
        spdlog::info("camera back: {} ({} reconnect(s) so far)", driver.describe(), s.reconnects);
      }
      in_error = false;
      rt.publish_heartbeat();  // monitors see the recovery now, not at the next period
    }
    switch (step.status) {
      case ReadStatus::kFrame: {
        const auto t0 = std::chrono::steady_clock::now();
        rt.publish(channel, step.image);
        const double publish_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        status.set_last_processed_seq(step.image.seq);
        status.record_latency_ms(step.convert_ms + publish_ms);
        // The preview after the frame: the detector has it already.
        if (const auto p = preview.offer(step.image)) rt.publish(preview_channel, *p);
        break;
      }
      case ReadStatus::kDisconnected:
        if (!in_error) {
          spdlog::error("camera lost: {}", step.reason);  // once per disconnection, not per retry
          status.set_state(status_t::STATE_ERROR, step.reason);
          status.set_error(step.reason);
          in_error = true;
          rt.publish_heartbeat();  // monitors see the loss now, not at the next period
        } else if (step.reason != status.last_error()) {
          status.set_state(status_t::STATE_ERROR, step.reason);
          status.set_error(step.reason);
        }
        break;
      case ReadStatus::kDropped:
      case ReadStatus::kTimeout:
      case ReadStatus::kEnd:
        break;
    }
    rt.heartbeat_if_due();
    if (driver.done()) {
      stop_reason = step.status == ReadStatus::kEnd ? "end of input" : "output.max_frames reached";
      break;
    }
  }
  const SourceStats& s = driver.source().stats();
  spdlog::info("{}: {} frames published, {} dropped, {} lost in sequence gaps, {} reconnects; {} previews on {}{}",
               stop_reason, driver.frames_out(), s.dropped + driver.driver_drops(), s.lost_in_gaps, s.reconnects,
               preview.made(), preview_channel,
               preview.failures() ? fmt::format(" ({} frames could not be previewed)", preview.failures()) : "");
  return rt.shutdown(stop_reason);
}

}  // namespace wingman::camera_driver
