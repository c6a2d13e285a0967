// SPDX-License-Identifier: MIT
// wingman-localizer: detections and own pose in, tracked 3D targets out.
#include <wingman/geometry/calibration.hpp>
#include "wingman/localizer/localizer.hpp"

#include <wingman/common/runtime.hpp>

#include <spdlog/spdlog.h>

namespace {

using namespace wingman;

int run(common::Runtime& rt, const localizer::LocalizerOptions& o) {
  localizer::Localizer loc(o, geometry::make_camera(o.camera));
  rt.status().declare_output(o.output_channel);
  if (o.windows.publish) rt.status().declare_output(o.windows.channel);
  // A time resync (one input re-anchored the clock) is worth a log line each time.
  const auto log_notes = [&] {
    for (const std::string& note : loc.take_notes()) spdlog::warn("{}", note);
  };
  rt.subscribe<own_pose_t>(o.own_pose_channel, [&](const own_pose_t& p) {
    loc.on_own_pose(p);
    log_notes();
  });
  rt.subscribe<detections_t>(o.detections_channel, [&](const detections_t& d) {
    const localizer::LocalizerOutput out = loc.on_detections(d);
    log_notes();
    rt.status().set_last_processed_seq(d.seq);
    for (const auto& why : out.rejections) rt.status().item_dropped(o.detections_channel, why);
    // Boxes of other classes than drone are expected, not drops: their counts since start are in the detail.
    // So are tracks the confidence bar holds back (a model scoring below it confirms nothing: the detail says why).
    std::string detail = loc.non_drone_boxes().summary();
    if (const std::string held = loc.tracker_summary(); !held.empty()) detail += (detail.empty() ? "" : "; ") + held;
    if (out.camera_frame_only) {
      rt.status().set_state(status_t::STATE_DEGRADED,
                            "camera frame only: no fresh own pose" + (detail.empty() ? "" : "; " + detail));
    } else {
      rt.status().set_state(status_t::STATE_OK, detail);
    }
    if (out.windows) rt.publish(o.windows.channel, *out.windows);  // before the targets: see LocalizerOutput
    if (out.targets) rt.publish(o.output_channel, *out.targets);
  });
  return rt.spin();
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"localizer", "wingman-localizer", "Localizes and tracks detected drones in 3D"};
  return common::run_process<localizer::LocalizerOptions>(info, argc, argv, run);
}
