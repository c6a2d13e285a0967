// SPDX-License-Identifier: MIT
// wingman-mavlink: the autopilot over MAVLink (serial or UDP); OWN_POSE out, SETPOINT in, safety rules in between.
#include "wingman/mavlink_bridge/bridge.hpp"
#include "wingman/mavlink_bridge/link.hpp"
#include "wingman/mavlink_bridge/link_reader.hpp"

#include <spdlog/spdlog.h>
#include <wingman/common/runtime.hpp>
#include <wingman/common/time.hpp>
#include <wingman/mavlink/parser.hpp>

namespace {

using namespace wingman;
using namespace wingman::mavlink_bridge;

/// The status channel entry of the MAVLink link (frames in, frames dropped by the parser).
const std::string kLinkChannel = "MAVLINK";
/// Reads of the link waiting to be handled at most (beyond: dropped and counted, memory stays bounded).
constexpr size_t kMaxQueuedChunks = 4096;
/// The main loop runs at least this often (ms): the setpoint stream (<= 200 Hz) and heartbeats are paced from it.
constexpr int kTickMs = 5;

/// Counts the parser's newly refused frames as drops on the link's status entry, one per frame.
void count_parser_drops(common::StatusTracker& status, const mavlink::ParserStats& now, mavlink::ParserStats& seen) {
  auto drops = [&](int64_t now_n, int64_t& seen_n, const char* what) {
    for (; seen_n < now_n; ++seen_n) status.input_dropped(kLinkChannel, std::string("MAVLink: ") + what);
  };
  drops(now.bad_crc, seen.bad_crc, "a frame with a bad checksum (dropped)");
  drops(now.bad_length, seen.bad_length, "a MAVLink 1 frame shorter than its message (dropped)");
  drops(now.signed_refused, seen.signed_refused, "a signed frame (signing is not implemented: refused)");
  drops(now.incompatible_flags, seen.incompatible_flags, "a frame with unknown incompatibility flags (refused)");
  drops(now.truncated, seen.truncated, "a frame cut off by the end of its datagram or stream (dropped)");
}

int run(common::Runtime& rt, const BridgeOptions& o) {
  LinkReader link(make_link(o.link_url, o.baud), o.reopen_period_s, kMaxQueuedChunks, [&rt] { rt.wake(); });
  mavlink::Parser parser;
  mavlink::ParserStats seen;
  Bridge bridge(o, [&](const std::string& reason, const std::string& message) {
    spdlog::warn("{} ({}; counted, logged once)", message, reason);
  });
  BridgeOutput out;
  int64_t write_failures = 0;
  auto flush = [&] {
    for (const auto& frame : out.frames)
      if (!link.write(frame)) ++write_failures;
    for (const auto& pose : out.poses) rt.publish(o.own_pose_channel, pose);
    out.frames.clear();
    out.poses.clear();
  };
  rt.status().declare_output(o.own_pose_channel);
  rt.status().declare_input(kLinkChannel);
  rt.subscribe<setpoint_t>(o.setpoint_channel, [&](const setpoint_t& sp) {
    bridge.on_setpoint(sp, common::monotonic_utime(), out);
    flush();
  });

  std::vector<LinkChunk> chunks;
  int64_t dropped_seen = 0;
  for (;;) {
    chunks.clear();
    link.take(chunks);
    // LCM before the link's reads: a SETPOINT that was on the bus before a read arrived is handled first, so an
    // answer to that read (TIMESYNC) comes after what the setpoint made us send (wingman-sim's lockstep barrier).
    rt.drain();
    for (const LinkChunk& c : chunks) {
      // Frames are handled with the clocks of the read that brought them (TIMESYNC round trips end there).
      auto on_frame = [&](const mavlink::Frame& f) {
        rt.status().input(kLinkChannel, 0);
        bridge.on_frame(f, c.mono_us, c.wall_ns, out);
      };
      if (!c.event.empty()) {
        if (c.lost) {
          parser.end_of_datagram(on_frame);
          rt.status().input_dropped(kLinkChannel, c.event + " (reopening)");
          spdlog::warn("{} (reopening every {} s)", c.event, o.reopen_period_s);
        } else if (c.event.rfind("link open", 0) == 0) {
          spdlog::info("{}", c.event);
        } else {
          rt.status().set_error(c.event);
          spdlog::warn("{} (retrying every {} s)", c.event, o.reopen_period_s);
        }
        continue;
      }
      parser.feed(c.bytes.data(), c.bytes.size(), on_frame);
      if (c.datagram) parser.end_of_datagram(on_frame);
    }
    for (const int64_t dropped = link.dropped_chunks(); dropped_seen < dropped; ++dropped_seen)
      rt.status().input_dropped(kLinkChannel, "MAVLink: input faster than it is handled: a read dropped (flood)");
    count_parser_drops(rt.status(), parser.stats(), seen);
    bridge.tick(common::monotonic_utime(), common::wall_utime() * 1000, out);
    flush();
    rt.status().set_state(bridge.healthy() ? status_t::STATE_OK : status_t::STATE_DEGRADED,
                          bridge.detail() + "; link " + link.describe() + (link.is_open() ? "" : " (closed)") + ": " +
                              parser.stats().summary() + ", write failures " + std::to_string(write_failures) +
                              ", reads dropped " + std::to_string(dropped_seen));
    // Woken by the link's reads and by LCM; otherwise at least every tick period for the stream and heartbeats.
    if (!rt.spin_once(kTickMs)) break;
  }
  spdlog::info("{}", bridge.detail());
  return rt.shutdown();
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"mavlink_bridge", "wingman-mavlink",
                                 "Bridges the pipeline to a PX4 or ArduPilot autopilot over MAVLink (serial or UDP)"};
  return common::run_process<BridgeOptions>(info, argc, argv, run);
}
