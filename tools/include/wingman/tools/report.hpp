// SPDX-License-Identifier: MIT
// `wingman report`: one self-contained HTML page (inline SVG and JPEG data URIs, opens offline) about a flight.
#pragma once

#include "wingman/tools/eval.hpp"

#include <string>

namespace wingman::tools {

/// A camera frame of the log drawn for the report.
struct ReportFrame {
  double t_s = 0.0;           ///< seconds since the first ground truth
  int64_t utime = 0;          ///< image_t.utime
  std::string jpeg_b64;       ///< the drawn frame, JPEG, base64
  int width = 0, height = 0;  ///< of the drawn (possibly scaled-down) frame, pixels
};

/// Reads up to options.report_frames images of options.image_channel spread evenly over result.image_utimes, and
/// draws each one's truth boxes (green: leader, grey: others), detections (red: single pass, orange: zoom-in) and
/// the leader's matched track id. Decodes BGR8, GRAY8, YUYV and MJPEG; frames that fail to decode are skipped.
std::vector<ReportFrame> draw_report_frames(const EvalResult& result, const EvalOptions& options);

/// The HTML page: summary table, top-down paths, errors over time, error by range, box width over distance,
/// latency histogram and the frames (or a note that the log has no images). Every chart is an <svg id="...">
/// whose data elements carry class="data".
std::string html_report(const EvalResult& result, const EvalOptions& options, const std::vector<ReportFrame>& frames);

/// draw_report_frames + html_report, written to `path`; throws std::runtime_error naming the file if it cannot.
void write_html_report(const EvalResult& result, const EvalOptions& options, const std::string& path);

}  // namespace wingman::tools
