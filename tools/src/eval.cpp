// SPDX-License-Identifier: MIT
// `wingman eval`: matches localized targets to simulator ground truth by utime and measures the errors. Reading is
// eval_read.cpp, the metrics eval_metrics.cpp, the text/JSON/CSV eval_report.cpp; the HTML page (report.hpp) builds
// on EvalResult and is written by its callers, so nothing here depends on it.
#include "wingman/tools/eval.hpp"

#include "eval_log.hpp"
#include "eval_metrics.hpp"

#include <fmt/format.h>
#include <wingman/recorder/channel_pattern.hpp>

#include <cmath>
#include <fstream>
#include <stdexcept>

namespace wingman::tools {

std::vector<std::string> EvalOptions::validate() const {
  std::vector<std::string> p;
  if (log.empty()) p.push_back("log: an LCM log file is required");
  if (truth_channel.empty()) p.push_back("--truth-channel: must not be empty");
  if (targets_channel.empty()) p.push_back("--targets-channel: must not be empty");
  if (std::string why; !recorder::ChannelPattern::compile(detections_channel, &why))
    p.push_back(fmt::format("--detections-channel: '{}' is not a channel pattern: {}", detections_channel, why));
  if (!(settle_s >= 0.0)) p.push_back(fmt::format("--settle: {} must be >= 0 seconds", settle_s));
  if (!(match_radius_m > 0.0)) p.push_back(fmt::format("--match-radius: {} must be > 0 metres", match_radius_m));
  if (follower_id == leader_id) p.push_back(fmt::format("--leader-id: {} must differ from --follower-id", leader_id));
  if (!formation_offset_in_world.allFinite()) p.push_back("--formation-offset: must be three finite numbers");
  for (size_t i = 0; i < range_bins_m.size(); ++i) {
    const double e = range_bins_m[i];
    if (!std::isfinite(e) || e <= 0.0 || (i > 0 && e <= range_bins_m[i - 1])) {
      p.push_back(
          fmt::format("--range-bins: {} (entry {}) must be finite, > 0 and greater than the one before it", e, i + 1));
      break;
    }
  }
  if (report_frames < 0) p.push_back(fmt::format("--frames: {} must be >= 0", report_frames));
  return p;
}

EvalResult evaluate_log(const EvalOptions& o) {
  if (const auto problems = o.validate(); !problems.empty()) {
    std::string all;
    for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
    throw std::invalid_argument("wingman eval: " + all);
  }
  const EvalLog log = read_eval_log(o);
  EvalResult r;
  log_metrics(log, &r);
  detection_metrics(log, o, &r);
  localization_metrics(log, o, &r);
  latency_metrics(log, &r);
  box_metrics(log, o, &r);
  formation_metrics(log, o, &r);

  const auto write = [](const std::string& path, const std::string& text) {
    std::ofstream f(path);
    f << text;
    if (!f) throw std::runtime_error("wingman eval: cannot write '" + path + "'");
  };
  if (!o.json_path.empty()) write(o.json_path, r.json() + "\n");
  if (!o.csv_path.empty()) write(o.csv_path, r.csv());
  return r;
}

}  // namespace wingman::tools
