// SPDX-License-Identifier: MIT
// `wingman demo-camera`: a video played through wingman-camera-driver into the running pipeline, recorded and
// summarised.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman demo-camera` plays and where it writes.
struct DemoCameraOptions {
  std::string video;               ///< the clip the camera driver plays once at its own rate (required)
  std::string out = "build/demo";  ///< output folder: demo.lcmlog, last_frame.png
  std::string bin_dir;             ///< the executables ("" = the folder of the running wingman)
  std::string lcm_url;             ///< the bus ("" = $WINGMAN_LCM_URL, set by tools/netns_run.sh)
  /// Wall seconds for every pipeline process's first heartbeat (the detector builds its OpenCL kernels).
  double start_timeout_s = 60.0;
  /// Wall seconds after the clip for the detector to account for every frame.
  double settle_timeout_s = 60.0;

  template <class V>
  void visit(V& v) {
    v("demo.video", video, "the clip the camera driver plays once at its own rate");
    v("demo.out", out, "output folder: demo.lcmlog, last_frame.png");
    v("demo.start_timeout_s", start_timeout_s, "wall seconds for every pipeline process's first heartbeat");
    v("demo.settle_timeout_s", settle_timeout_s, "wall seconds after the clip for the detector to settle");
    v("run.bin_dir", bin_dir, "the executables; \"\" = the folder of this wingman");
    v("run.lcm_url", lcm_url, "the bus; \"\" = $WINGMAN_LCM_URL (tools/netns_run.sh sets it)");
  }
  /// Every problem with the values, one line each.
  std::vector<std::string> validate() const;
};

/// Starts lcm-logger, wingman-detector, wingman-localizer and wingman-follower-ctrl (their built-in defaults), waits
/// for their heartbeats, plays the clip through wingman-camera-driver, waits until the detector's heartbeat accounts
/// for every frame on the bus (detected or counted as dropped), stops everything and prints what the log holds
/// (`wingman loginfo`, the last frame saved as out/last_frame.png). Returns the exit code: 0; 1 when a process fails or
/// ends early (named on `err`) or a wait runs out; 130 on SIGINT/SIGTERM. Throws std::invalid_argument for bad options.
int run_demo_camera(const DemoCameraOptions& o, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
