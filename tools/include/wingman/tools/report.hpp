// SPDX-License-Identifier: MIT
// `wingman report`: one self-contained HTML page (inline SVG and JPEG data URIs, opens offline) about a flight.
#pragma once

#include "wingman/tools/eval.hpp"

#include <string>
#include <vector>

namespace wingman::tools {

/// Width of the camera-frame thumbnails in the report, pixels (smaller frames keep their size).
inline constexpr int kReportThumbnailWidth = 320;

/// A camera frame of the log drawn for the report.
struct ReportFrame {
  double t_s = 0.0;           ///< seconds since the first ground truth
  int64_t utime = 0;          ///< image_t.utime
  std::string jpeg_b64;       ///< the drawn thumbnail, JPEG, base64
  int width = 0, height = 0;  ///< of the thumbnail (at most kReportThumbnailWidth wide), pixels
};

/// Reads up to options.report_frames images of options.image_channel spread evenly over result.image_utimes, scales
/// each down to kReportThumbnailWidth and draws its truth boxes (green: leader, grey: others), detections (red:
/// single pass, orange: zoom-in) and the leader's matched track id. Decodes BGR8, GRAY8, YUYV and MJPEG; frames that
/// fail to decode are skipped.
std::vector<ReportFrame> draw_report_frames(const EvalResult& result, const EvalOptions& options);

/// Round axis ticks ("nice numbers"): the step is 1, 2 or 5 times a power of ten, the smallest such step (and at
/// least min_step) for which the multiples of it enclosing [lo, hi] span at most max_intervals intervals; the axis
/// runs from the first to the last of those multiples. lo == hi gets the one step around it; non-finite input
/// gives 0..1.
struct AxisTicks {
  double lo = 0.0, hi = 1.0, step = 1.0;
  std::vector<double> values;  ///< lo, lo + step, ..., hi
};
AxisTicks nice_ticks(double lo, double hi, int max_intervals = 6, double min_step = 0.0);

/// A tick's label for an axis of that step: as many decimals as the step needs (none for steps of 1 or more),
/// thousands as "k" and millions as "M" when the step is at least that large ("2k", "1.5M"), never "-0".
std::string tick_label(double value, double step);

/// One figure of the report's headline block.
struct HeadlineItem {
  std::string key;    ///< localization_rms, formation_rms, detection_rate, false_targets, track_ids, latency
  std::string label;  ///< what it is, for people
  bool measured = false;
  std::vector<double> values;  ///< the eval's numbers it shows (see report_headline), empty when not measured
  std::string text;            ///< the figure as shown ("0.30 m"), or "not measured"
  std::string detail;          ///< sample size and definition, or why it is not measured
  std::string thesis;          ///< the thesis's (2018) figure beside it; "" where the thesis has none
};

/// The headline, in this order, each from `result` alone:
/// localization_rms {localization.rms} (thesis: 2.86 m, its real flights' average RMS),
/// formation_rms {formation_horizontal.rms}, detection_rate {frames_leader_detected, frames_leader_visible},
/// false_targets {false_targets, false_track_ids}, track_ids {track_ids_on_leader, leader_id_switches},
/// latency {latency_ms.p50, latency_ms.p99} (thesis: about 0.7 s lag in flight).
/// A figure without data (no matched estimate, no formation target, no visible leader or no detections_t, no
/// world-valid target, no latency sample) is "not measured", never 0.
std::vector<HeadlineItem> report_headline(const EvalResult& result);

/// The HTML page: the headline table (id="headline"), the camera-frame thumbnails (or a note, id="no-images", that
/// the log has no images), top-down paths, errors over time, error by range, box width over distance, latency
/// histogram, and every number as text. Every chart is an <svg id="..."> whose data elements carry class="data";
/// its axes have round ticks (nice_ticks) and a margin sized from the widest tick label.
std::string html_report(const EvalResult& result, const EvalOptions& options, const std::vector<ReportFrame>& frames);

/// draw_report_frames + html_report, written to `path`; throws std::runtime_error naming the file if it cannot.
void write_html_report(const EvalResult& result, const EvalOptions& options, const std::string& path);

}  // namespace wingman::tools
