// SPDX-License-Identifier: MIT
// `wingman eval`, reading: the flight log's ground truth, targets, detections and image utimes as records.
#include "eval_log.hpp"
#include "lcm_fingerprint.hpp"
#include "log_progress.hpp"

#include <fmt/format.h>
#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/common/message_validation.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/geometry/message_eigen.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/recorder/channel_pattern.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <unordered_map>

namespace wingman::tools {
namespace {

/// Decodes and validates `ev` as Msg; false (counted by the caller) when it is not one or is malformed.
template <class Msg>
bool decode(const common::LcmLogEvent& ev, Msg* m) {
  if (lcm_fingerprint(ev.data, ev.datalen) != static_cast<uint64_t>(Msg::getHash())) return false;
  if (m->decode(ev.data, 0, ev.datalen) < 0) return false;
  return common::validate_message(*m).empty();
}

/// The utime of an image_t event without decoding its pixels (right after the fingerprint, big-endian); nullopt when
/// the event is not an image_t.
std::optional<int64_t> image_utime(const common::LcmLogEvent& ev) {
  if (ev.datalen < 16 || lcm_fingerprint(ev.data, ev.datalen) != static_cast<uint64_t>(wingman::image_t::getHash()))
    return std::nullopt;
  const auto* p = static_cast<const uint8_t*>(ev.data) + 8;
  uint64_t u = 0;
  for (int i = 0; i < 8; ++i) u = (u << 8) | p[i];
  return static_cast<int64_t>(u);
}

void add_truth(const wingman::ground_truth_t& g, int64_t timestamp, EvalLog* log) {
  ++log->truth_frames;
  for (const auto& v : g.vehicles) {
    TruthTrack& t = log->truth[v.vehicle_id];
    if (!t.utime.empty() && g.utime <= t.utime.back()) continue;  // keep times strictly increasing
    t.utime.push_back(g.utime);
    t.p.push_back(geometry::to_vector3(v.p_body_in_world));
  }
  log->truth_boxes_at[g.utime] = g.boxes;
  log->truth_event_at.emplace(g.utime, timestamp);
}

void add_targets(const wingman::targets_t& ts, int64_t timestamp, size_t index, EvalLog* log) {
  int64_t newest = INT64_MIN;
  for (const auto& t : ts.targets) {
    newest = std::max(newest, t.source_utime);
    if (t.world_valid) log->estimates.push_back({t.predicted_utime, index, t});
  }
  if (!ts.targets.empty()) log->published.emplace_back(timestamp, newest);
}

void add_detections(const wingman::detections_t& d, EvalLog* log) {
  log->sources.insert(d.source);
  log->inference_ms.push_back(d.inference_latency_us * 1e-3);
  // Drone boxes only, as the localizer tracks them; the other classes are counted apart.
  std::vector<wingman::detection_t> drones;
  for (const auto& b : d.detections) {
    if (b.class_id == 0)
      drones.push_back(b);
    else
      ++log->non_drone_boxes;
  }
  log->detections.push_back({d.utime, d.camera_id, d.image_width, std::move(drones)});
}

}  // namespace

bool TruthTrack::at(int64_t t, Eigen::Vector3d* out) const {
  if (utime.empty() || t < utime.front() || t > utime.back()) return false;
  const auto it = std::lower_bound(utime.begin(), utime.end(), t);
  const size_t i = static_cast<size_t>(it - utime.begin());
  if (utime[i] == t || i == 0) {
    *out = p[i];
    return true;
  }
  const double a = static_cast<double>(t - utime[i - 1]) / static_cast<double>(utime[i] - utime[i - 1]);
  *out = (1.0 - a) * p[i - 1] + a * p[i];
  return true;
}

EvalLog read_eval_log(const EvalOptions& o) {
  if (std::filesystem::is_directory(o.log))
    throw std::runtime_error("wingman eval: the log '" + o.log + "' is a directory");
  std::ifstream probe(o.log, std::ios::binary);
  if (!probe) throw std::runtime_error("wingman eval: cannot read the log '" + o.log + "'");
  probe.close();
  common::LcmLogReader file(o.log);  // a corrupt event throws, naming its byte offset

  EvalLog log;
  size_t targets_messages = 0;
  // Whether a channel is a detections channel (o.detections_channel matched once per channel name).
  std::string why;
  const std::optional<recorder::ChannelPattern> detections_pattern =
      recorder::ChannelPattern::compile(o.detections_channel, &why);
  if (!detections_pattern)
    throw std::runtime_error(
        fmt::format("wingman eval: detections channel '{}' is not a channel pattern: {}", o.detections_channel, why));
  std::unordered_map<std::string, bool> is_detections;
  auto detections_channel = [&](const std::string& channel) {
    const auto [it, inserted] = is_detections.try_emplace(channel, false);
    if (inserted) it->second = detections_pattern->matches(channel);
    return it->second;
  };
  common::Progress progress = log_progress(o.progress, "wingman: reading " + o.log, o.log);
  while (const common::LcmLogEvent* ev = file.read_next()) {
    progress.update(ev->offset);
    if (ev->channel == o.truth_channel) {
      wingman::ground_truth_t g;
      if (decode(*ev, &g)) add_truth(g, ev->timestamp, &log);
    } else if (ev->channel == o.targets_channel) {
      wingman::targets_t ts;
      if (decode(*ev, &ts)) add_targets(ts, ev->timestamp, targets_messages++, &log);
    } else if (detections_channel(ev->channel)) {
      wingman::detections_t d;
      if (decode(*ev, &d)) add_detections(d, &log);
    } else if (ev->channel.rfind("STATUS_DETECTOR", 0) == 0 && !log.detector_backends.count(ev->channel)) {
      // The detector's heartbeat says which backend runs, and why, while nothing else needs saying.
      wingman::status_t s;
      if (decode(*ev, &s) && s.detail.rfind("backend ", 0) == 0) log.detector_backends[ev->channel] = s.detail;
    } else if (ev->channel == o.image_channel || ev->channel == o.preview_channel) {
      // Only the utime: the pixels are read by the report when needed.
      if (const std::optional<int64_t> u = image_utime(*ev); u && ev->channel == o.image_channel) {
        log.image_utimes.push_back(*u);
        log.image_event_at.emplace(*u, ev->timestamp);
      } else if (u) {
        log.preview_utimes.push_back(*u);
      }
    }
  }
  progress.update(progress.total());
  progress.finish();
  if (log.truth.empty()) {
    throw std::runtime_error("wingman eval: '" + o.log + "' holds no ground_truth_t on channel " + o.truth_channel);
  }
  return log;
}

}  // namespace wingman::tools
