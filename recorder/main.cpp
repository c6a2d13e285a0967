// SPDX-License-Identifier: MIT
// wingman-recorder: every LCM channel (but images, by default) into size-rotated LCM log files.
#include "wingman/recorder/recorder.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/common/runtime.hpp>
#include <wingman/common/time.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <lcm/lcm-cpp.hpp>

#include <memory>
#include <stdexcept>

namespace {

using namespace wingman;

/// Receives every channel on its own LCM instance (raw bytes: nothing is decoded) and queues the wanted ones.
struct Tap {
  recorder::Recorder* rec;
  recorder::ChannelFilter filter;
  common::StatusTracker* status;

  void on_event(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (!filter.wants(channel)) return;
    // The event time is LCM's receive time, as lcm-logger writes it; the payload is stored as received.
    if (rec->record(channel, rbuf->recv_utime, rbuf->data, rbuf->data_size)) status->input(channel, 0);
  }
};

/// Turns the recorder's counters into the heartbeat: drops per channel, state and one error line per failure.
class Monitor {
 public:
  Monitor(recorder::Recorder& rec, common::StatusTracker& status, double retry_period_s)
      : rec_(rec), status_(status), retry_period_s_(retry_period_s) {}

  void update() {
    for (const auto& [channel, count] : rec_.take_drops()) {
      status_.source_dropped(channel, count, "channel " + channel + ": event dropped by the recorder");
    }
    const recorder::RecorderStats s = rec_.stats();
    if (s.failing && !failing_) {
      failing_ = true;
      written_at_failure_ = s.events_written;
      dropped_at_failure_ = s.dropped_write_error;
      spdlog::error("{}; dropping events, trying a new segment every {} s", s.last_error, retry_period_s_);
    } else if (failing_ && !s.failing && s.events_written > written_at_failure_) {
      failing_ = false;
      spdlog::info("recording resumed in {} ({} events dropped meanwhile)", s.segment,
                   s.dropped_write_error - dropped_at_failure_);
    }
    if (!s.last_error.empty()) status_.set_error(s.last_error);
    if (failing_) {
      status_.set_state(status_t::STATE_ERROR, fmt::format("not recording: {}; {} events dropped, retrying every {} s",
                                                           s.last_error, s.dropped_write_error, retry_period_s_));
    } else if (s.dropped_queue_full > queue_drops_seen_) {
      status_.set_state(status_t::STATE_DEGRADED,
                        fmt::format("recording to {}: disk too slow, {} events dropped (queue full)", s.segment,
                                    s.dropped_queue_full));
    } else {
      status_.set_state(status_t::STATE_OK, fmt::format("recording to {} ({} events, {:.1f} MiB written)", s.segment,
                                                        s.events_written, s.bytes_written / (1024.0 * 1024.0)));
    }
    queue_drops_seen_ = s.dropped_queue_full;
  }

 private:
  recorder::Recorder& rec_;
  common::StatusTracker& status_;
  double retry_period_s_;
  bool failing_ = false;
  int64_t written_at_failure_ = 0;
  int64_t dropped_at_failure_ = 0;
  int64_t queue_drops_seen_ = 0;
};

int run(common::Runtime& rt, const recorder::RecorderOptions& o) {
  const common::RuntimeOptions& ro = rt.options();
  const std::string url = ro.lcm_in.empty() ? ro.lcm_url : ro.lcm_in;
  const bool from_file = url.rfind("file://", 0) == 0;
  // A log input is read with headers checked before allocating (LCM's own reader crashed on a corrupt length).
  std::unique_ptr<common::LcmLogReader> log;
  std::unique_ptr<lcm::LCM> bus;
  if (from_file) {
    common::LcmLogReadOptions read_options;
    read_options.skip_corrupt = ro.skip_corrupt_log;
    log = std::make_unique<common::LcmLogReader>(common::parse_lcm_file_url(url).path, read_options);
  } else {
    bus = std::make_unique<lcm::LCM>(url);
    if (!bus->good()) throw std::runtime_error("cannot open LCM input '" + url + "'");
  }

  recorder::Recorder rec(o);  // throws (exit 1) only with errors.require_directory_at_start
  Monitor monitor(rec, rt.status(), o.retry_period_s);
  monitor.update();
  const recorder::RecorderStats first = rec.stats();
  if (!first.failing) spdlog::info("recording to {}", first.segment);

  Tap tap{&rec, recorder::ChannelFilter(o.include, o.exclude), &rt.status()};
  if (bus) bus->subscribe(".*", &Tap::on_event, &tap);
  std::string reason;
  int64_t corrupt_counted = 0;
  while (!rt.stop_requested()) {
    if (log) {
      const common::LcmLogEvent* ev = log->read_next();  // corrupt: throws naming the offset, unless skipped
      if (log->corrupt_events() > corrupt_counted) {
        rt.status().items_dropped(url, log->corrupt_events() - corrupt_counted, log->first_corruption());
        spdlog::warn("{} (skipped: --skip-corrupt-log)", log->first_corruption());
        corrupt_counted = log->corrupt_events();
      }
      if (ev == nullptr) {
        rec.wait_idle(10.0);  // a log read as input is recorded completely
        reason = "end of input log";
        break;
      }
      lcm::ReceiveBuffer rbuf{};
      rbuf.data = const_cast<void*>(ev->data);
      rbuf.data_size = static_cast<uint32_t>(ev->datalen);
      rbuf.recv_utime = common::wall_utime();  // as LCM's file provider delivered it: the receive time is now
      tap.on_event(&rbuf, ev->channel);
    } else if (bus->handleTimeout(100) < 0 && !rt.stop_requested()) {
      throw std::runtime_error("LCM input failed while waiting for messages");
    }
    monitor.update();
    rt.heartbeat_if_due();
  }
  rec.close(0.5);  // SIGTERM: what is still queued gets half a second, the rest is dropped and counted
  monitor.update();
  const recorder::RecorderStats s = rec.stats();
  spdlog::info("recorded {} events ({:.1f} MiB) in {} segments; dropped {} (queue full) + {} (write errors)",
               s.events_written, s.bytes_written / (1024.0 * 1024.0), s.segments_opened, s.dropped_queue_full,
               s.dropped_write_error);
  return rt.shutdown(reason);
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"recorder", "wingman-recorder", "Records LCM channels into rotated LCM log files"};
  return common::run_process<recorder::RecorderOptions>(info, argc, argv, run);
}
