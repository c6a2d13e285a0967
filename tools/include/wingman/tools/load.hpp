// SPDX-License-Identifier: MIT
// `wingman load`: the four-camera load test and the soak (the thesis's 360-degree case) through the real processes.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman load` runs. Camera N is a wingman-camera-driver (camera_N) playing a 1280x720 30-fps clip in a loop
/// on IMAGE_CAM<N> (output.encoding `encoding`); detector_N (the shipped model) detects in it; one localizer fuses the
/// cameras of the rig file `rig` (cameras.rig: camera N's DETECTIONS_CAM<N>, its mount yawed 90 degrees per camera)
/// into one track set on TARGETS, as the vehicle does; one follower_ctrl follows TARGETS. Relative paths are taken
/// from the working directory (tools/load_test.sh runs it from the checkout's root).
struct LoadOptions {
  std::string mode = "realtime";  ///< realtime (cameras paced at 30 fps) or replay (detectors file to file)
  double duration_s = 0.0;        ///< realtime: seconds the cameras play (0: 30, or 600 with soak)
  std::string out;                ///< output folder ("" = build/load/MODE, build/load/soak with soak)
  int cameras = 4;                ///< camera chains, 1..4
  bool soak = false;              ///< realtime, plus the RSS growth check and the latency trend
  double warmup_s = 0.0;  ///< soak: seconds before RSS is taken as the reference (0: 30 up to 180-s runs, else 60)
  double sample_period_s = 2.0;  ///< seconds between RSS/CPU samples from /proc
  int replay_frames = 10;        ///< replay: frames per camera
  /// Camera images on the bus (each driver's output.encoding): mjpeg (JPEG at jpeg_quality) or raw (BGR8, 2.7 MB a
  /// frame). mjpeg: four raw 720p streams overflow every socket's receive buffer (docs/reliability.md, "Load and
  /// soak", where the two are measured side by side).
  std::string encoding = "mjpeg";
  int jpeg_quality = 90;  ///< the drivers' output.jpeg_quality, 1..100
  int max_width = 0;      ///< the drivers' output.max_width (downscaled frames; the localizer scales the rig); 0 = 1280
  std::string rig = "config/rigs/surround4.yaml";  ///< the localizer's cameras.rig (made absolute); camera ids 0..3
  double max_p99_s = 5.0;                          ///< realtime: bound on the end-to-end p99, seconds
  double max_rss_growth_pct = 5.0;                 ///< soak: bound on RSS growth after the warm-up, percent
  bool report_only = false;  ///< speed and memory bounds reported, not checked (frame accounting still is)
  std::string summary_script = "tools/load_summary.py";  ///< the figures and checks (Python, generated LCM types)
  std::string bin_dir;                                   ///< the executables ("" = the folder of the running wingman)
  std::string lcm_url;  ///< realtime's bus ("" = $WINGMAN_LCM_URL, set by tools/netns_run.sh)

  template <class V>
  void visit(V& v) {
    v("load.mode", mode, "realtime (cameras paced at 30 fps) or replay (detectors file to file)");
    v("load.duration_s", duration_s, "realtime: seconds the cameras play; 0 = 30, or 600 with soak");
    v("load.out", out, "output folder; \"\" = build/load/MODE (build/load/soak with soak)");
    v("load.cameras", cameras, "camera chains, 1..4");
    v("load.soak", soak, "realtime, plus the RSS growth check and the latency trend");
    v("load.warmup_s", warmup_s, "soak: seconds before RSS is the reference; 0 = 30 up to 180-s runs, else 60");
    v("load.sample_period_s", sample_period_s, "seconds between RSS/CPU samples from /proc");
    v("load.replay_frames", replay_frames, "replay: frames per camera");
    v("load.encoding", encoding, "camera images on the bus (the drivers' output.encoding): mjpeg or raw");
    v("load.jpeg_quality", jpeg_quality, "the drivers' output.jpeg_quality with mjpeg, 1..100");
    v("load.max_width", max_width,
      "the drivers' output.max_width: frames downscaled to it (the localizer's camera.scale_to_image); 0 = 1280");
    v("load.rig", rig, "the localizer's camera rig (cameras.rig), one camera per chain, camera ids 0..3");
    v("checks.max_p99_s", max_p99_s, "realtime: bound on the end-to-end p99, seconds");
    v("checks.max_rss_growth_pct", max_rss_growth_pct, "soak: bound on RSS growth after the warm-up, percent");
    v("checks.report_only", report_only, "speed and memory bounds reported, not checked (frame accounting still is)");
    v("run.summary_script", summary_script, "the figures and checks (Python, the generated LCM types)");
    v("run.bin_dir", bin_dir, "the executables; \"\" = the folder of this wingman");
    v("run.lcm_url", lcm_url, "realtime's bus; \"\" = $WINGMAN_LCM_URL (tools/netns_run.sh sets it)");
  }
  /// Every problem with the values, one line each ("load.cameras = 5: must be 1..4").
  std::vector<std::string> validate() const;
  /// duration_s and warmup_s with their defaults applied.
  double effective_duration_s() const;
  double effective_warmup_s() const;
};

/// The command-line options of process `exe` for camera chain `camera` (0-based) of a load run, as --set pairs: what
/// the process reads over its built-in defaults. `exe`: wingman-detector, wingman-localizer (the one fusing localizer:
/// `o.rig`, absolute; `camera` unused), wingman-camera-driver (`clip`, `realtime` pacing or fast from a fixed start
/// time with `max_frames`, `o.encoding` at `o.jpeg_quality`) or wingman-follower-ctrl.
std::vector<std::string> load_process_sets(const std::string& exe, int camera, const std::string& clip, bool realtime,
                                           int max_frames, bool detector_realtime, const LoadOptions& o);

/// Runs the load test: prints what it does and the summary's figures on `out`, and returns 0 when every check
/// passed, 1 when one failed (named on `err`), 130 on SIGINT/SIGTERM. Throws std::invalid_argument for bad options.
int run_load(const LoadOptions& o, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
