// SPDX-License-Identifier: MIT
// Summary of an LCM log: channels, types (by fingerprint), counts, utime spans, statuses, a snapshot.
#include "wingman/tools/log_info.hpp"

#include "lcm_fingerprint.hpp"
#include "log_progress.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/common/message_validation.hpp>
#include <wingman/detector/preprocess.hpp>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>

#include <functional>
#include <stdexcept>

namespace wingman::tools {
namespace {

/// Decodes and validates one message of a known type; returns its utime or -1.
using Decoder = std::function<int64_t(const void*, int, std::string*)>;

template <class Msg>
std::pair<uint64_t, std::pair<std::string, Decoder>> entry() {
  Decoder d = [](const void* data, int size, std::string* line) -> int64_t {
    Msg m;
    if (m.decode(data, 0, size) < 0) return -1;
    if (!common::validate_message(m).empty()) return -1;
    if constexpr (std::is_same_v<Msg, wingman::status_t>) {
      static const char* kStates[] = {"STARTING", "OK", "DEGRADED", "ERROR", "STOPPING"};
      *line = fmt::format("{} '{}', handled {}, drops {}, last seq {}, p50 {:.2f} ms{}", kStates[m.state], m.detail,
                          m.messages_handled, m.drops_total, m.last_processed_seq, m.latency_p50_ms,
                          m.last_error.empty() ? "" : ", last error: " + m.last_error);
    }
    return m.utime;
  };
  return {static_cast<uint64_t>(Msg::getHash()), {Msg::getTypeName(), d}};
}

}  // namespace

LogSummary summarize_log(const std::string& log_path, const std::string& snapshot_png, bool skip_corrupt,
                         std::ostream* progress) {
  common::LcmLogReadOptions read_options;
  read_options.skip_corrupt = skip_corrupt;
  common::LcmLogReader log(log_path, read_options);  // a corrupt event throws, naming its byte offset
  const std::map<uint64_t, std::pair<std::string, Decoder>> types = {
      entry<wingman::image_t>(),       entry<wingman::detections_t>(), entry<wingman::own_pose_t>(),
      entry<wingman::targets_t>(),     entry<wingman::setpoint_t>(),   entry<wingman::status_t>(),
      entry<wingman::ground_truth_t>()};
  LogSummary summary;
  std::map<std::string, size_t> index;
  std::vector<uint8_t> last_image;
  common::Progress read = log_progress(progress, "wingman loginfo: reading " + log_path, log_path);
  while (const common::LcmLogEvent* ev = log.read_next()) {
    read.update(ev->offset);
    auto [it, fresh] = index.emplace(ev->channel, summary.channels.size());
    if (fresh)
      summary.channels.push_back(ChannelSummary{ev->channel, ev->channel == "LCM_SELF_TEST" ? "(LCM internal)" : "?"});
    ChannelSummary& c = summary.channels[it->second];
    ++c.count;
    c.bytes += ev->datalen;
    const uint64_t fp = lcm_fingerprint(ev->data, ev->datalen);
    const auto t = types.find(fp);
    if (t == types.end()) continue;
    c.type = t->second.first;
    std::string status_line;
    const int64_t utime = t->second.second(ev->data, ev->datalen, &status_line);
    if (utime < 0) {
      ++c.undecodable;
      continue;
    }
    if (c.first_utime == 0) c.first_utime = utime;
    c.last_utime = utime;
    if (!status_line.empty()) {
      wingman::status_t s;
      s.decode(ev->data, 0, ev->datalen);
      summary.statuses[s.process] = status_line;
    }
    if (fp == static_cast<uint64_t>(wingman::image_t::getHash())) {
      const auto* p = static_cast<const uint8_t*>(ev->data);
      last_image.assign(p, p + ev->datalen);
    }
  }
  read.update(read.total());
  read.finish();
  if (!last_image.empty()) {
    wingman::image_t img;
    img.decode(last_image.data(), 0, static_cast<int>(last_image.size()));
    const cv::Mat bgr = detector::image_to_bgr(img, nullptr);
    if (!bgr.empty()) {
      ++summary.images_with_pixels;
      if (!snapshot_png.empty() && !cv::imwrite(snapshot_png, bgr))
        throw std::runtime_error(fmt::format("{}: cannot write the snapshot", snapshot_png));
    }
  }
  summary.corrupt_events = log.corrupt_events();
  summary.corrupt_bytes = log.skipped_bytes();
  summary.first_corruption = log.first_corruption();
  return summary;
}

std::string LogSummary::report() const {
  std::string s =
      fmt::format("{:<20} {:<22} {:>7} {:>11} {:>9} {:>8}\n", "channel", "type", "count", "bytes", "span [s]", "bad");
  for (const auto& c : channels) {
    const double span = c.count > 1 && c.last_utime > c.first_utime ? (c.last_utime - c.first_utime) * 1e-6 : 0.0;
    s += fmt::format("{:<20} {:<22} {:>7} {:>11} {:>9.2f} {:>8}\n", c.channel, c.type, c.count, c.bytes, span,
                     c.undecodable);
  }
  if (corrupt_events > 0)
    s += fmt::format("corrupt: {} stretch(es), {} bytes skipped; the first: {}\n", corrupt_events, corrupt_bytes,
                     first_corruption);
  if (!statuses.empty()) {
    s += "last status of each process:\n";
    for (const auto& [process, line] : statuses) s += fmt::format("  {:<16} {}\n", process, line);
  }
  return s;
}

}  // namespace wingman::tools
