// SPDX-License-Identifier: MIT
// wingman-localizer: detections and own pose in, tracked 3D targets out.
#include "wingman/localizer/localizer.hpp"

#include <wingman/common/runtime.hpp>

#include <spdlog/spdlog.h>

namespace {

using namespace wingman;

int run(common::Runtime& rt, const localizer::LocalizerOptions& o) {
  // One camera (camera.*), or the cameras of cameras.rig, each with its own detections and windows channels.
  localizer::Localizer loc = localizer::Localizer::from_options(o);
  rt.status().declare_output(o.output_channel);
  if (o.windows.publish)
    for (const localizer::LocalizerCamera& c : loc.cameras()) rt.status().declare_output(c.windows_channel);
  // A time resync (one input re-anchored the clock) is worth a log line each time.
  const auto log_notes = [&] {
    for (const std::string& note : loc.take_notes()) spdlog::warn("{}", note);
  };
  rt.subscribe<own_pose_t>(o.own_pose_channel, [&](const own_pose_t& p) {
    loc.on_own_pose(p);
    log_notes();
  });
  bool camera_frame_only = false;  // the newest exposure had no fresh own pose
  for (const localizer::LocalizerCamera& camera : loc.cameras()) {
    const std::string channel = camera.detections_channel;
    // A message that cannot be used throws: the runtime drops and counts it on its channel, never fatal.
    rt.subscribe<detections_t>(channel, [&](const detections_t& d) {
      const std::vector<localizer::LocalizerOutput> outputs = loc.add_detections(d);
      log_notes();
      rt.status().set_last_processed_seq(d.seq);
      for (const localizer::LocalizerOutput& out : outputs) {
        for (size_t i = 0; i < out.rejections.size(); ++i)  // on the channel of the camera it belongs to
          rt.status().item_dropped(out.rejection_channels[i], out.rejections[i]);
        camera_frame_only = out.camera_frame_only;
      }
      // Boxes of other classes than drone are expected, not drops: their counts since start are in the detail.
      // So are tracks the confidence bar holds back (a model scoring below it confirms nothing: the detail says why),
      // and with a camera rig the detections per camera and the silent cameras.
      std::string detail;
      const auto add = [&detail](const std::string& part) {
        if (!part.empty()) detail += (detail.empty() ? "" : "; ") + part;
      };
      const std::string silent = loc.silent_summary();
      add(silent);
      add(loc.cameras_summary());
      add(loc.non_drone_boxes().summary());
      add(loc.tracker_summary());
      if (camera_frame_only) {
        rt.status().set_state(status_t::STATE_DEGRADED,
                              "camera frame only: no fresh own pose" + (detail.empty() ? "" : "; " + detail));
      } else {
        rt.status().set_state(silent.empty() ? status_t::STATE_OK : status_t::STATE_DEGRADED, detail);
      }
      for (const localizer::LocalizerOutput& out : outputs) {
        // Windows before the targets: see LocalizerOutput.
        if (out.windows) rt.publish(o.windows.channel, *out.windows);
        for (const localizer::CameraWindows& w : out.camera_windows) rt.publish(w.channel, w.windows);
        if (out.targets) rt.publish(o.output_channel, *out.targets);
      }
    });
  }
  return rt.spin();
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"localizer", "wingman-localizer", "Localizes and tracks detected drones in 3D"};
  return common::run_process<localizer::LocalizerOptions>(info, argc, argv, run);
}
