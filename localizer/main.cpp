// SPDX-License-Identifier: MIT
// wingman-localizer: detections and own pose in, tracked 3D targets out (tracking arrives with the localizer issue).
#include "wingman/localizer/localizer_options.hpp"

#include <wingman/common/runtime.hpp>

int main(int argc, char** argv) {
  using namespace wingman;
  const common::ProcessInfo info{"localizer", "wingman-localizer", "Localizes and tracks detected drones in 3D"};
  return common::run_process<localizer::LocalizerOptions>(
      info, argc, argv, [](common::Runtime& rt, const localizer::LocalizerOptions& o) {
        rt.status().declare_output(o.output_channel);
        rt.status().set_state(status_t::STATE_DEGRADED, "no localization yet: inputs are checked and counted only");
        rt.subscribe<detections_t>(o.detections_channel,
                                   [&rt](const detections_t& d) { rt.status().set_last_processed_seq(d.seq); });
        rt.subscribe<own_pose_t>(o.own_pose_channel, [](const own_pose_t&) {});
        return rt.spin();
      });
}
