// SPDX-License-Identifier: MIT
// `wingman replay`: plays an LCM log, optionally in lockstep with the pipeline's processes.
#include "wingman/tools/replay.hpp"

#include "log_progress.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/launcher/bus_watch.hpp>
#include <wingman/status_t.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>
#include <lcm/lcm-cpp.hpp>
#include <wingman/common/config.hpp>

#include <chrono>
#include <map>
#include <memory>
#include <regex>
#include <set>
#include <stdexcept>
#include <thread>

namespace wingman::tools {
namespace {

using Clock = std::chrono::steady_clock;

bool is_status_channel(const std::string& channel) { return channel.rfind("STATUS_", 0) == 0; }
/// LCM's udpm provider publishes one LCM_SELF_TEST message when a process starts; it is not pipeline traffic.
bool is_lcm_internal(const std::string& channel) { return channel == "LCM_SELF_TEST"; }

/// What the player counts and records from the bus (the stages' heartbeats: a launcher::BusWatch on the same LCM).
class BusObserver {
 public:
  explicit BusObserver(lcm::LogFile* record) : record_(record) {}

  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (is_status_channel(channel) || is_lcm_internal(channel)) return;
    ++bus_counts_[channel];
    if (record_ != nullptr) {
      lcm::LogEvent ev;
      ev.eventnum = 0;
      ev.timestamp = current_event_utime_;  // the played event's time: deterministic, unlike the receive clock
      ev.channel = channel;
      ev.datalen = static_cast<int32_t>(rbuf->data_size);
      ev.data = rbuf->data;
      if (record_->writeEvent(&ev) != 0) throw std::runtime_error("cannot write to the record log");
      ++recorded_;
    }
  }

  std::map<std::string, int64_t> bus_counts_;  ///< messages seen per channel since start
  int64_t current_event_utime_ = 0;
  int64_t recorded_ = 0;

 private:
  lcm::LogFile* record_;
};

/// Input counts of a stage at the start, so messages it handled before the replay do not count.
using Baseline = std::map<std::string, std::map<std::string, int64_t>>;

/// "" when every stage has handled every message on its input channels, else what is missing. Every stage has
/// reported (`watch` holds its newest status).
std::string unsettled(const BusObserver& bus, const launcher::BusWatch& watch, const std::vector<std::string>& stages,
                      const Baseline& baseline) {
  for (const auto& name : stages) {
    const auto& s = *watch.status(name);
    for (const auto& c : s.channels) {
      if (c.direction != wingman::channel_stats_t::DIRECTION_IN) continue;
      // Heartbeats are wall-clock liveness, never played nor counted (a follower watches STATUS_LOCALIZER): a
      // stage's count of them says nothing about the replay having settled.
      if (is_status_channel(c.channel)) continue;
      const auto it = bus.bus_counts_.find(c.channel);
      const int64_t on_bus = it == bus.bus_counts_.end() ? 0 : it->second;
      const int64_t handled = c.count - baseline.at(name).at(c.channel);
      if (handled != on_bus) {
        return fmt::format("stage '{}' handled {} of {} messages on {}", name, handled, on_bus, c.channel);
      }
    }
  }
  return "";
}

}  // namespace

std::vector<std::string> ReplayOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (input_log.empty()) p.emplace_back("input.log: give the log to play (LOG, or the key)");
  if (speed < 0) p.push_back(problem("playback.speed", speed, "must be >= 0"));
  if (start_timeout_s <= 0) p.push_back(problem("lockstep.start_timeout_s", start_timeout_s, "must be > 0 seconds"));
  if (step_timeout_s <= 0) p.push_back(problem("lockstep.step_timeout_s", step_timeout_s, "must be > 0 seconds"));
  if (max_events < 0) p.push_back(problem("input.max_events", static_cast<double>(max_events), "must be >= 0"));
  return p;
}

std::string ReplaySummary::one_line() const {
  std::string s = fmt::format("replay {}: {} events played, {} skipped, {} recorded, {:.2f} s", ok ? "done" : "FAILED",
                              events_played, events_skipped, messages_recorded, wall_s);
  if (corrupt_events > 0) s += fmt::format(", {} corrupt stretch(es) of the log skipped", corrupt_events);
  if (!error.empty()) s += ": " + error;
  return s;
}

ReplaySummary run_replay(const ReplayOptions& options) {
  if (const auto bad = options.validate(); !bad.empty())
    throw std::runtime_error(fmt::format("{}", fmt::join(bad, "; ")));
  const auto t_start = Clock::now();
  ReplaySummary summary;

  common::LcmLogReadOptions read_options;
  read_options.skip_corrupt = options.skip_corrupt;
  common::LcmLogReader in(options.input_log, read_options);  // a corrupt event throws, naming its byte offset
  std::unique_ptr<lcm::LogFile> record;
  if (!options.record_log.empty()) {
    record = std::make_unique<lcm::LogFile>(options.record_log, "w");
    if (!record->good())
      throw std::runtime_error(fmt::format("{}: cannot open record log for writing", options.record_log));
  }
  lcm::LCM lcm(options.lcm_url);
  if (!lcm.good()) throw std::runtime_error(fmt::format("cannot open LCM URL '{}'", options.lcm_url));

  std::regex include_re, exclude_re;
  try {
    if (!options.channels.empty()) include_re = std::regex(options.channels);
    if (!options.exclude.empty()) exclude_re = std::regex(options.exclude);
  } catch (const std::regex_error& e) {
    throw std::runtime_error(fmt::format("--channels/--exclude: not a valid regular expression: {}", e.what()));
  }

  BusObserver bus(record.get());
  lcm.subscribe(".*", &BusObserver::on_message, &bus);
  launcher::BusWatch watch(lcm);  // the stages' heartbeats, handled by the same spins as everything else
  const bool lockstep = !options.stages.empty();

  // Lockstep: wait until every stage reports, and remember where its counters start.
  Baseline baseline;
  std::set<std::string> stage_outputs;
  if (lockstep) {
    const double waited_s = std::chrono::duration<double>(Clock::now() - t_start).count();
    const auto missing = watch.wait_for_status(options.stages, options.start_timeout_s - waited_s);
    if (!missing.empty()) {
      summary.error = fmt::format("no status from {} within {} s (started with --lockstep on this LCM URL?)",
                                  fmt::join(missing, ", "), options.start_timeout_s);
      summary.wall_s = std::chrono::duration<double>(Clock::now() - t_start).count();
      return summary;
    }
    for (const auto& name : options.stages) {
      for (const auto& c : watch.status(name)->channels) {
        if (c.direction == wingman::channel_stats_t::DIRECTION_IN)
          baseline[name][c.channel] = c.count;
        else if (!is_status_channel(c.channel))
          stage_outputs.insert(c.channel);
      }
    }
    // Messages a stage saw before the replay (heartbeats excluded) are not ours to wait for.
    bus.bus_counts_.clear();
  }

  int64_t first_timestamp = -1;
  const auto play_start = Clock::now();
  common::Progress progress = log_progress(options.progress, "wingman replay: " + options.input_log, options.input_log);
  while (options.max_events == 0 || summary.events_played < options.max_events) {
    const common::LcmLogEvent* ev = in.read_next();
    summary.corrupt_events = in.corrupt_events();
    if (ev == nullptr) break;
    progress.update(ev->offset);
    const bool play = !is_status_channel(ev->channel) && !is_lcm_internal(ev->channel) &&
                      !stage_outputs.count(ev->channel) &&
                      (options.channels.empty() || std::regex_match(ev->channel, include_re)) &&
                      (options.exclude.empty() || !std::regex_match(ev->channel, exclude_re));
    if (!play) {
      ++summary.events_skipped;
      continue;
    }
    if (!lockstep && options.speed > 0) {
      if (first_timestamp < 0) first_timestamp = ev->timestamp;
      const double due_s = static_cast<double>(ev->timestamp - first_timestamp) * 1e-6 / options.speed;
      std::this_thread::sleep_until(play_start +
                                    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(due_s)));
    }
    bus.current_event_utime_ = ev->timestamp;
    const int64_t expected = bus.bus_counts_[ev->channel] + 1;
    if (lcm.publish(ev->channel, ev->data, static_cast<unsigned int>(ev->datalen)) != 0) {
      throw std::runtime_error(fmt::format("channel {}: LCM failed to publish {} bytes", ev->channel, ev->datalen));
    }
    ++summary.events_played;
    if (!lockstep) {
      while (lcm.handleTimeout(0) > 0) {
      }
      continue;
    }
    // Wait for our own message to come back, then for every stage to have handled everything.
    const auto deadline = Clock::now() + std::chrono::duration<double>(options.step_timeout_s);
    std::string why;
    for (;;) {
      why = bus.bus_counts_[ev->channel] < expected ? "own message not seen on the bus"
                                                    : unsettled(bus, watch, options.stages, baseline);
      if (why.empty()) break;
      if (Clock::now() > deadline) {
        summary.error = fmt::format("event {} (channel {}): not settled within {} s: {}", summary.events_played,
                                    ev->channel, options.step_timeout_s, why);
        summary.messages_recorded = bus.recorded_;
        summary.wall_s = std::chrono::duration<double>(Clock::now() - t_start).count();
        return summary;
      }
      lcm.handleTimeout(20);
    }
  }
  progress.finish();
  if (!lockstep) {
    // Let the last messages arrive for the record (bounded).
    const auto until = Clock::now() + std::chrono::milliseconds(300);
    while (Clock::now() < until) lcm.handleTimeout(20);
  }
  if (watch.bad_messages() > 0)
    spdlog::warn("{} status messages could not be decoded and were ignored", watch.bad_messages());
  summary.ok = true;
  summary.messages_recorded = bus.recorded_;
  summary.wall_s = std::chrono::duration<double>(Clock::now() - t_start).count();
  return summary;
}

}  // namespace wingman::tools
