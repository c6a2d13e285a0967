// SPDX-License-Identifier: MIT
// The process runtime every Wingman process uses: CLI, config, LCM in/out, typed subscriptions that
// drop and count bad messages, status heartbeats, signals, and one-line fatal errors.
#pragma once

#include "wingman/common/config.hpp"
#include "wingman/common/lcm_log_reader.hpp"
#include "wingman/common/message_limits.hpp"
#include "wingman/common/message_validation.hpp"
#include "wingman/common/status_tracker.hpp"

#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <regex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace wingman::common {

/// What a process is (fixed in its main).
struct ProcessInfo {
  std::string name;         ///< instance name default and config stem, e.g. "camera_driver"
  std::string executable;   ///< e.g. "wingman-camera-driver"
  std::string description;  ///< one line for --help
};

/// Options common to every process, from the command line (not the YAML file).
struct RuntimeOptions {
  /// --config FILE (repeatable, read in order: a later file's keys win) and --set KEY=VALUE (repeatable, applied
  /// after every file); none = built-in defaults.
  ConfigSources config;
  bool print_config = false;       ///< --print-config: print the effective config and exit 0
  std::string lcm_url;             ///< --lcm-url; "" = LCM_DEFAULT_URL or LCM's default
  std::string lcm_in;              ///< --lcm-in: URL to read from; "" = lcm_url
  std::string lcm_out;             ///< --lcm-out: URL to publish to; "" = lcm_url
  std::string instance;            ///< --name: instance name in status and its channel; "" = ProcessInfo::name
  bool lockstep = false;           ///< --lockstep: publish status after every handled message (for `wingman replay`)
  double status_period_s = 1.0;    ///< --status-period: heartbeat period, seconds (wall clock)
  std::string log_level = "info";  ///< --log-level: trace, debug, info, warn, error
  /// --skip-corrupt-log: a corrupt event of a file:// input is skipped and counted (as drops of the input log)
  /// instead of ending the process with exit 1 and a line naming its byte offset.
  bool skip_corrupt_log = false;
  /// --watchdog S: when the process's loop makes no progress (no spin_once() returns, e.g. a handler that never
  /// ends) for S seconds after start-up, one line `<executable>: error: watchdog: ...` and exit 1, so the supervisor
  /// restarts it. Seconds of wall time, 0 = off (default), else 0.1..3600. Under systemd with WatchdogSec, the
  /// same progress also pings the service manager (sd_notify WATCHDOG=1), which catches a stopped process too.
  double watchdog_s = 0.0;

  /// "" or one line naming the bad option.
  std::string validate() const;
};

/// Channel on which process instance `instance` publishes its status_t: "STATUS_" + upper case.
std::string status_channel(const std::string& instance);

/// LCM I/O and bookkeeping for one process. Single-threaded: handlers run inside spin_once(), and every member
/// but wake() is for the thread that spins. A process that works on another thread (the real-time detector)
/// hands its results back to that thread and calls wake() so they are published without waiting for a message.
class Runtime {
 public:
  /// Opens the LCM URLs and installs SIGINT/SIGTERM handlers. Throws std::runtime_error naming the
  /// URL when LCM cannot be opened.
  Runtime(const ProcessInfo& info, const RuntimeOptions& options);
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  const std::string& instance() const { return instance_; }
  const RuntimeOptions& options() const { return options_; }
  StatusTracker& status() { return status_; }
  /// True when the input is an LCM log file (file:// URL): the process ends at its end.
  bool input_is_file() const { return input_is_file_; }

  /// Subscribes to `channel` with messages of type Msg. Each message is decoded and checked with
  /// `validate` (default: validate_message); a message that fails either, or whose handler throws,
  /// is dropped and counted (status drops, last_error) — the process keeps running.
  template <class Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                 std::function<std::string(const Msg&)> validate = default_validator<Msg>());

  /// Publishes on `channel` (to --lcm-out) and counts it. Throws std::runtime_error naming the
  /// channel if LCM fails to publish.
  template <class Msg>
  void publish(const std::string& channel, const Msg& msg);

  /// Handles incoming messages for up to `timeout_ms` and publishes the heartbeat when due.
  /// Returns false when the process should end: SIGINT/SIGTERM, request_stop(), or end of a file input.
  bool spin_once(int timeout_ms = 100);
  /// Handles every message already waiting, without blocking (at most `max_messages`). A process
  /// that keeps only the newest input calls it before working, so stale inputs are superseded.
  /// Returns the number handled. Not for file inputs (there every message is handled in turn).
  int drain(int max_messages = 1000);
  /// Makes the spin_once() in progress, or the next one, return before its timeout (its messages handled first).
  /// The one member that may be called from any thread.
  void wake();
  /// Whether subscriptions record their handler's run time as the status latency (default true). A process whose
  /// handler only queues work (and records the work's time itself with status().record_latency_ms) turns it off.
  void set_record_handler_latency(bool record) { record_handler_latency_ = record; }
  /// spin_once() until it returns false, then shutdown(). Returns 0.
  int spin();
  /// Sets the state to STOPPING with `reason` (default: the signal or end of input) and publishes a
  /// final heartbeat. Processes with their own loop (sources) call it before returning. Returns 0.
  int shutdown(const std::string& reason = "");
  /// Publishes the heartbeat now when it is due (sources call this from their own loop).
  void heartbeat_if_due();
  /// Publishes a heartbeat now.
  void publish_heartbeat();

  bool stop_requested() const;
  void request_stop(const std::string& reason);

  /// Limits every subscription checks before decoding (default: MessageLimits{}). Throws std::invalid_argument
  /// naming the limit when `limits` is invalid.
  void set_message_limits(const MessageLimits& limits);
  const MessageLimits& message_limits() const { return message_limits_; }

 private:
  class SubscriptionBase {
   public:
    virtual ~SubscriptionBase() = default;
  };
  template <class Msg>
  class Subscription;

  /// Handles one raw message of a channel (a Subscription's on_message).
  using RawHandler = std::function<void(const lcm::ReceiveBuffer*, const std::string&)>;
  /// A subscription on a file:// input, read by LcmLogReader (LCM's own log reader is not used: it allocates
  /// from unchecked length fields).
  void subscribe_file(const std::string& channel, RawHandler handler);
  /// spin_once() for a file:// input: one event per call (paced by the URL's speed), dispatched to the
  /// subscriptions whose channel matches.
  bool spin_file_once(int timeout_ms);

  template <class Msg>
  static std::function<std::string(const Msg&)> default_validator() {
    return [](const Msg& m) { return validate_message(m); };
  }
  void after_message();
  /// The input LCM instance, opened on first use (throws naming the URL if it cannot be opened).
  lcm::LCM& input();
  void publish_raw(const std::string& channel, const void* data, size_t size);

  ProcessInfo info_;
  RuntimeOptions options_;
  std::string instance_;
  std::string status_channel_;
  std::vector<uint8_t> publish_buffer_;  ///< encoding buffer of publish(), reused
  std::string in_url_;
  std::unique_ptr<lcm::LCM> lcm_in_;
  std::unique_ptr<lcm::LCM> lcm_out_owned_;
  lcm::LCM* lcm_out_ = nullptr;
  bool input_is_file_ = false;
  bool end_of_input_ = false;
  std::unique_ptr<LcmLogReader> log_in_;      ///< a file:// input, opened on first use
  double log_speed_ = 1.0;                    ///< its ?speed= (0: as fast as possible)
  const LcmLogEvent* log_pending_ = nullptr;  ///< the next event, read but not yet due (speed > 0)
  int64_t log_first_utime_ = -1;
  std::chrono::steady_clock::time_point log_start_;
  int64_t log_corrupt_counted_ = 0;  ///< corrupt stretches already counted as drops
  std::vector<std::pair<std::regex, RawHandler>> file_subscriptions_;
  StatusTracker status_;
  MessageLimits message_limits_;
  std::vector<std::unique_ptr<SubscriptionBase>> subscriptions_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_heartbeat_;
  std::string stop_reason_;
  bool stop_requested_locally_ = false;
  bool record_handler_latency_ = true;
  int wake_fd_ = -1;  ///< eventfd that wake() writes and spin_once() waits on beside LCM's descriptor
  /// The progress watchdog (--watchdog, systemd's WATCHDOG_USEC): a thread started at the first spin_once().
  void start_watchdog();
  void note_progress();
  std::atomic<int64_t> progress_ns_{0};  ///< steady clock of the last loop progress
  std::atomic<bool> watchdog_stop_{false};
  bool watchdog_checked_ = false;  ///< start_watchdog() has decided whether a thread is needed
  std::thread watchdog_;
};

template <class Msg>
class Runtime::Subscription : public Runtime::SubscriptionBase {
 public:
  Subscription(Runtime* rt, std::string channel, std::function<void(const Msg&)> handler,
               std::function<std::string(const Msg&)> validate)
      : rt_(rt), channel_(std::move(channel)), handler_(std::move(handler)), validate_(std::move(validate)) {}

  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    // The same path as the fuzz targets (tests/fuzz): wire-format and size checks before decoding, then
    // decode, then validation; anything wrong drops and counts the message, naming the channel and field.
    Msg msg;
    const std::string problem = decode_message<Msg>(rbuf->data, rbuf->data_size, rt_->message_limits_, msg, validate_);
    if (!problem.empty()) {
      rt_->status_.input_dropped(channel_, "channel " + channel_ + ": " + problem);
      rt_->after_message();
      return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      handler_(msg);
      rt_->status_.input(channel_, msg.utime);
    } catch (const std::exception& e) {
      rt_->status_.input_dropped(channel_, "channel " + channel_ + ": " + e.what());
    }
    const auto t1 = std::chrono::steady_clock::now();
    if (rt_->record_handler_latency_)
      rt_->status_.record_latency_ms(std::chrono::duration<double, std::milli>(t1 - t0).count());
    rt_->after_message();
  }

 private:
  Runtime* rt_;
  std::string channel_;
  std::function<void(const Msg&)> handler_;
  std::function<std::string(const Msg&)> validate_;
};

template <class Msg>
void Runtime::subscribe(const std::string& channel, std::function<void(const Msg&)> handler,
                        std::function<std::string(const Msg&)> validate) {
  if (!knows_encoding(Msg::getTypeName()))
    throw std::invalid_argument(std::string("subscribe: no wire-format check for ") + Msg::getTypeName() +
                                " (add it to common/src/message_limits.cpp)");
  auto sub = std::make_unique<Subscription<Msg>>(this, channel, std::move(handler), std::move(validate));
  // LCM treats the channel as a regular expression; anchor it so "IMAGE" does not match "IMAGE_2".
  if (input_is_file_) {
    Subscription<Msg>* s = sub.get();
    subscribe_file(channel, [s](const lcm::ReceiveBuffer* rbuf, const std::string& ch) { s->on_message(rbuf, ch); });
  } else {
    input().subscribe("^" + channel + "$", &Subscription<Msg>::on_message, sub.get());
  }
  status_.declare_input(channel);
  subscriptions_.push_back(std::move(sub));
}

template <class Msg>
void Runtime::publish(const std::string& channel, const Msg& msg) {
  // One buffer reused for every message: no allocation per frame once it has grown to the largest.
  const int size = msg.getEncodedSize();
  if (publish_buffer_.size() < static_cast<size_t>(size)) publish_buffer_.resize(static_cast<size_t>(size));
  if (msg.encode(publish_buffer_.data(), 0, size) < 0) {
    throw std::runtime_error("channel " + channel + ": cannot encode " + Msg::getTypeName());
  }
  publish_raw(channel, publish_buffer_.data(), static_cast<size_t>(size));
  status_.output(channel, msg.utime);
}

/// Sets up logging, parses the common options, `--config` and `--set`, builds the Runtime and runs `body`.
/// Turns every error into one line on stderr and an exit code: 0 on success, SIGINT/SIGTERM or end
/// of a file input; 2 for a bad command line or config; 1 for any other fatal error.
/// `load_config(sources, print)` loads the options (throws ConfigError) and returns, when `print`, the
/// `--print-config` text.
int run_process_impl(const ProcessInfo& info, int argc, char** argv,
                     const std::function<std::string(const ConfigSources& sources, bool print)>& load_config,
                     const std::function<int(Runtime&)>& body);

/// run_process_impl for an `Options` struct with visit() and validate() (see ConfigLoader), loaded from the
/// layered --config files and --set overrides.
template <class Options>
int run_process(const ProcessInfo& info, int argc, char** argv,
                const std::function<int(Runtime&, const Options&)>& body) {
  Options options;
  auto load = [&](const ConfigSources& sources, bool print) -> std::string {
    options = load_options<Options>(sources);
    if (!print) return "";
    return print_options(options,
                         info.executable + " effective configuration" +
                             (sources.empty() ? " (built-in defaults)" : " (from " + sources.describe() + ")"));
  };
  return run_process_impl(info, argc, argv, std::function<std::string(const ConfigSources&, bool)>(load),
                          [&](Runtime& rt) { return body(rt, options); });
}

}  // namespace wingman::common
