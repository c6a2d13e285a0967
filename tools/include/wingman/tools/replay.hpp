// SPDX-License-Identifier: MIT
// `wingman replay`: plays an LCM log into the pipeline, optionally in lockstep with its processes.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman replay`.
struct ReplayOptions {
  std::string input_log;            ///< LCM log to play
  bool skip_corrupt = false;        ///< skip (and count) corrupt events of input_log instead of failing at the first
  std::string lcm_url;              ///< bus to publish on and listen to; "" = LCM_DEFAULT_URL or LCM's default
  std::vector<std::string> stages;  ///< lockstep: process instance names (status_t.process) to wait for
  std::string channels;             ///< regular expression of channels to play; "" = all
  std::string exclude;              ///< regular expression of channels not to play; "" = none
  std::string record_log;           ///< write every non-status message seen on the bus here; "" = none
  double speed = 1.0;               ///< without stages: 1 = the log's real time, 0 = as fast as possible
  double start_timeout_s = 10.0;    ///< lockstep: seconds to wait for every stage's first status
  double step_timeout_s = 5.0;      ///< lockstep: seconds to wait for the pipeline to settle after one message
  int64_t max_events = 0;           ///< play at most this many events; 0 = all
  /// Progress through the log (common::Progress, every 5 s) goes here; nullptr = quiet.
  std::ostream* progress = nullptr;

  /// Every problem, one line each named by `wingman replay`'s key (input.log, playback.speed, lockstep.*,
  /// input.max_events); empty when valid.
  std::vector<std::string> validate() const;
};

/// What a replay did.
struct ReplaySummary {
  bool ok = false;
  int64_t events_played = 0;      ///< messages published from the log
  int64_t events_skipped = 0;     ///< log events not played (status, filtered, or stage outputs)
  int64_t corrupt_events = 0;     ///< corrupt stretches of the input log skipped (skip_corrupt)
  int64_t messages_recorded = 0;  ///< messages written to the record log
  double wall_s = 0.0;            ///< wall-clock duration
  std::string error;              ///< why it failed, "" when ok

  std::string one_line() const;
};

/// Plays `options.input_log`.
///
/// Lockstep (stages not empty): waits until every stage has published a status_t, then publishes
/// one event at a time and waits until the pipeline has settled before the next: every stage has
/// handled, on each channel it subscribes to (its status lists them), as many messages as have
/// appeared on the bus since the replay started. Messages the stages produce in response are part
/// of the bus count, so a chain (images → detections → targets) settles fully before the next event.
/// Channels a stage publishes are not played from the log (the stage makes them anew). Stages must
/// run with `--lockstep` so their status follows every message. With one publisher per channel,
/// each channel's sequence of payloads is then the same run after run.
///
/// Without stages, plays at `speed` times the log's pace (by the log's event timestamps).
///
/// Throws std::runtime_error for a missing or unreadable log or a bad URL; a stage that does not
/// report or settle in time makes the summary not ok, naming the stage and channel.
ReplaySummary run_replay(const ReplayOptions& options);

}  // namespace wingman::tools
