// SPDX-License-Identifier: MIT
// Process runtime: command line, config, LCM endpoints, heartbeats, signals and error reporting.
#include "wingman/common/runtime.hpp"
#include "wingman/common/version.hpp"

#include "wingman/common/time.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/un.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>

namespace wingman::common {
namespace {

std::atomic<int> g_signal{0};
/// True until the process first waits for input or asks whether to stop: start-up (config, model loading, OpenCL
/// kernel builds) may take seconds in calls that cannot be interrupted, and nothing needs a final status yet.
std::atomic<bool> g_starting{true};

extern "C" void on_signal(int sig) {
  // A stop asked for during start-up ends the process at once (exit 0 within the 1 s the supervisor is promised).
  // The exit_group system call itself, not _exit(): sanitizers intercept _exit with code that is not
  // async-signal-safe (ThreadSanitizer's finalisation allocates and can deadlock here; google/sanitizers#1440).
  if (g_starting.load()) syscall(SYS_exit_group, 0);
  g_signal.store(sig);
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: blocking calls return EINTR so loops notice promptly
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
}

bool is_file_url(const std::string& url) { return url.rfind("file://", 0) == 0; }

std::unique_ptr<lcm::LCM> open_lcm(const std::string& url, const char* role) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    const std::string shown = url.empty() ? "the default URL (LCM_DEFAULT_URL or udpm default)" : "'" + url + "'";
    throw std::runtime_error(fmt::format("cannot open LCM {} {}", role, shown));
  }
  return lcm;
}

}  // namespace

std::string RuntimeOptions::validate() const {
  if (!(status_period_s > 0.0 && status_period_s <= 60.0))
    return fmt::format("--status-period = {}: must be in (0, 60] seconds", status_period_s);
  static const std::vector<std::string> levels = {"trace", "debug", "info", "warn", "error"};
  if (std::find(levels.begin(), levels.end(), log_level) == levels.end())
    return fmt::format("--log-level = '{}': must be one of trace, debug, info, warn, error", log_level);
  if (is_file_url(lcm_url) && lcm_url.find("mode=") != std::string::npos && lcm_url.find("mode=r") == std::string::npos)
    return fmt::format("--lcm-url = '{}': a log opened for writing cannot also be the input; use --lcm-out for it",
                       lcm_url);
  if (!(watchdog_s == 0.0 || (watchdog_s >= 0.1 && watchdog_s <= 3600.0)))
    return fmt::format("--watchdog = {}: must be 0 (off) or in [0.1, 3600] seconds", watchdog_s);
  if (const std::string in = lcm_in.empty() ? lcm_url : lcm_in; is_file_url(in)) {
    try {
      parse_lcm_file_url(in);
    } catch (const std::invalid_argument& e) {
      return fmt::format("{}: {}", lcm_in.empty() ? "--lcm-url" : "--lcm-in", e.what());
    }
  }
  if (is_file_url(lcm_out) && lcm_out.find("mode=w") == std::string::npos &&
      lcm_out.find("mode=a") == std::string::npos)
    return fmt::format("--lcm-out = '{}': a file output needs '?mode=w' (or mode=a)", lcm_out);
  return "";
}

void Runtime::set_message_limits(const MessageLimits& limits) {
  const std::string problem = limits.validate();
  if (!problem.empty()) throw std::invalid_argument("message limits: " + problem);
  message_limits_ = limits;
}

std::string status_channel(const std::string& instance) {
  std::string ch = "STATUS_";
  for (char c : instance) ch += std::isalnum(static_cast<unsigned char>(c)) ? static_cast<char>(std::toupper(c)) : '_';
  return ch;
}

Runtime::Runtime(const ProcessInfo& info, const RuntimeOptions& options)
    : info_(info),
      options_(options),
      instance_(options.instance.empty() ? info.name : options.instance),
      status_channel_(status_channel(instance_)),
      status_(instance_, static_cast<int32_t>(getpid())) {
  install_signal_handlers();
  wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0)
    throw std::runtime_error(fmt::format("cannot create the wake-up eventfd: {}", std::strerror(errno)));
  const std::string in_url = options_.lcm_in.empty() ? options_.lcm_url : options_.lcm_in;
  const std::string out_url = options_.lcm_out.empty() ? options_.lcm_url : options_.lcm_out;
  input_is_file_ = is_file_url(in_url);
  in_url_ = in_url;
  // The output opens now; the input only when the process subscribes or spins, so a pure source
  // (the camera driver writing to a file) never opens a multicast socket it does not need.
  if (out_url == in_url && !input_is_file_) {
    lcm_in_ = open_lcm(in_url, "bus");
    lcm_out_ = lcm_in_.get();
  } else {
    lcm_out_owned_ = open_lcm(out_url, "output");
    lcm_out_ = lcm_out_owned_.get();
  }
  start_ = std::chrono::steady_clock::now();
  last_heartbeat_ = start_;
  status_.declare_output(status_channel_);
  spdlog::debug("lcm in '{}', out '{}', status on {}", in_url, out_url, status_channel_);
}

Runtime::~Runtime() {
  watchdog_stop_.store(true);
  if (watchdog_.joinable()) watchdog_.join();
  if (wake_fd_ >= 0) close(wake_fd_);
}

namespace {

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// sd_notify(0, message) without libsystemd: one datagram to $NOTIFY_SOCKET ("@name": abstract). False when there is
/// no socket to tell.
bool notify_service_manager(const char* message) {
  const char* path = std::getenv("NOTIFY_SOCKET");
  if (path == nullptr || path[0] == '\0' || std::strlen(path) >= sizeof(sockaddr_un{}.sun_path)) return false;
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return false;
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path, sizeof(addr.sun_path) - 1);
  if (path[0] == '@') addr.sun_path[0] = '\0';
  const socklen_t len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + std::strlen(path));
  const bool ok =
      sendto(fd, message, std::strlen(message), MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(&addr), len) >= 0;
  close(fd);
  return ok;
}

}  // namespace

void Runtime::note_progress() { progress_ns_.store(steady_ns(), std::memory_order_relaxed); }

void Runtime::start_watchdog() {
  note_progress();
  if (watchdog_checked_) return;
  watchdog_checked_ = true;
  const char* usec = std::getenv("WATCHDOG_USEC");
  const int64_t systemd_ns = usec != nullptr ? std::strtoll(usec, nullptr, 10) * 1000 : 0;
  const int64_t own_ns = static_cast<int64_t>(options_.watchdog_s * 1e9);
  if (own_ns <= 0 && systemd_ns <= 0) return;
  notify_service_manager("READY=1");
  const std::string executable = info_.executable;
  const double watchdog_s = options_.watchdog_s;
  watchdog_ = std::thread([this, own_ns, systemd_ns, executable, watchdog_s] {
    // Checks often enough to react within a tenth of the bound (at least every 100 ms).
    const int64_t tick_ns = std::min<int64_t>(
        100000000,
        std::max<int64_t>(1000000,
                          std::min(own_ns > 0 ? own_ns : INT64_MAX, systemd_ns > 0 ? systemd_ns : INT64_MAX) / 10));
    int64_t last_ping = 0;
    while (!watchdog_stop_.load()) {
      std::this_thread::sleep_for(std::chrono::nanoseconds(tick_ns));
      const int64_t now = steady_ns();
      const int64_t idle = now - progress_ns_.load(std::memory_order_relaxed);
      if (own_ns > 0 && idle > own_ns) {
        // The loop is stuck (e.g. a handler that never returns): say so and exit, so the supervisor restarts us.
        std::fprintf(stderr, "%s: error: watchdog: the main loop made no progress for %.1f s (--watchdog %g)\n",
                     executable.c_str(), static_cast<double>(idle) * 1e-9, watchdog_s);
        std::fflush(stderr);
        std::_Exit(1);
      }
      // systemd (WatchdogSec): ping at half its interval, and only while the loop progresses.
      if (systemd_ns > 0 && idle < systemd_ns / 2 && now - last_ping >= systemd_ns / 2) {
        notify_service_manager("WATCHDOG=1");
        last_ping = now;
      }
    }
  });
}

void Runtime::wake() {
  const uint64_t one = 1;
  // EAGAIN means the counter is already non-zero: a wake-up is pending either way.
  [[maybe_unused]] const ssize_t n = write(wake_fd_, &one, sizeof one);
}

bool Runtime::stop_requested() const {
  // A process that asks has a loop that honours the answer: start-up is over (see on_signal).
  g_starting.store(false);
  return g_signal.load() != 0 || stop_requested_locally_;
}

void Runtime::request_stop(const std::string& reason) {
  stop_requested_locally_ = true;
  stop_reason_ = reason;
}

void Runtime::publish_raw(const std::string& channel, const void* data, size_t size) {
  if (lcm_out_->publish(channel, data, static_cast<unsigned int>(size)) != 0) {
    throw std::runtime_error(fmt::format("channel {}: LCM failed to publish {} bytes", channel, size));
  }
}

void Runtime::publish_heartbeat() {
  const auto now = std::chrono::steady_clock::now();
  const double window_s = std::chrono::duration<double>(now - last_heartbeat_).count();
  const int64_t uptime_us = std::chrono::duration_cast<std::chrono::microseconds>(now - start_).count();
  last_heartbeat_ = now;
  const wingman::status_t s = status_.heartbeat(wall_utime(), uptime_us, window_s);
  try {
    publish(status_channel_, s);  // counted as an output like any other message
  } catch (const std::exception& e) {
    spdlog::warn("channel {}: failed to publish the status heartbeat: {}", status_channel_, e.what());
  }
}

void Runtime::heartbeat_if_due() {
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_heartbeat_).count() >= options_.status_period_s) publish_heartbeat();
}

void Runtime::after_message() {
  if (options_.lockstep) publish_heartbeat();
}

lcm::LCM& Runtime::input() {
  if (!lcm_in_) lcm_in_ = open_lcm(in_url_, input_is_file_ ? "input log" : "input");
  return *lcm_in_;
}

void Runtime::subscribe_file(const std::string& channel, RawHandler handler) {
  file_subscriptions_.emplace_back(std::regex("^" + channel + "$"), std::move(handler));
}

bool Runtime::spin_file_once(int timeout_ms) {
  if (!log_in_) {
    const LcmFileUrl url = parse_lcm_file_url(in_url_);
    LcmLogReadOptions read_options;
    read_options.skip_corrupt = options_.skip_corrupt_log;
    try {
      log_in_ = std::make_unique<LcmLogReader>(url.path, read_options);
    } catch (const LcmLogError& e) {
      throw std::runtime_error(fmt::format("cannot open LCM input log '{}': {}", in_url_, e.what()));
    }
    log_speed_ = url.speed;
  }
  if (status_.state() == wingman::status_t::STATE_STARTING) status_.set_state(wingman::status_t::STATE_OK, "");
  if (!log_pending_) {
    log_pending_ = log_in_->read_next();  // a corrupt event throws (exit 1 naming its offset) unless skipped
    if (log_in_->corrupt_events() > log_corrupt_counted_) {
      const int64_t n = log_in_->corrupt_events() - log_corrupt_counted_;
      log_corrupt_counted_ = log_in_->corrupt_events();
      const std::string line =
          fmt::format("{} (skipped: --skip-corrupt-log; {} corrupt stretch(es), {} bytes so far)",
                      log_in_->first_corruption(), log_in_->corrupt_events(), log_in_->skipped_bytes());
      spdlog::warn("{}", line);
      status_.items_dropped(in_url_, n, line);
    }
    if (!log_pending_) {
      end_of_input_ = true;
      stop_reason_ = "end of input log";
      heartbeat_if_due();
      return false;
    }
  }
  if (log_speed_ > 0) {  // the log's pace, divided by the speed
    const auto now = std::chrono::steady_clock::now();
    if (log_first_utime_ < 0) {
      log_first_utime_ = log_pending_->timestamp;
      log_start_ = now;
    }
    const double due_s = static_cast<double>(log_pending_->timestamp - log_first_utime_) * 1e-6 / log_speed_;
    const auto due = log_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(std::max(0.0, due_s)));
    if (now < due) {
      const auto wait_ms = std::chrono::duration_cast<std::chrono::milliseconds>(due - now).count() + 1;
      pollfd fd{wake_fd_, POLLIN, 0};
      if (poll(&fd, 1, static_cast<int>(std::min<int64_t>(std::max(0, timeout_ms), wait_ms))) > 0) {
        uint64_t count = 0;
        [[maybe_unused]] const ssize_t n = read(wake_fd_, &count, sizeof count);
      }
      heartbeat_if_due();
      return !stop_requested();
    }
  }
  const LcmLogEvent* ev = log_pending_;
  log_pending_ = nullptr;
  lcm::ReceiveBuffer rbuf{};
  rbuf.data = const_cast<void*>(ev->data);
  rbuf.data_size = static_cast<uint32_t>(ev->datalen);
  rbuf.recv_utime = ev->timestamp;
  for (auto& [re, handle] : file_subscriptions_) {
    if (std::regex_match(ev->channel, re)) handle(&rbuf, ev->channel);
  }
  heartbeat_if_due();
  return !stop_requested();
}

bool Runtime::spin_once(int timeout_ms) {
  g_starting.store(false);
  start_watchdog();  // start-up is over: from here on the loop must keep coming back
  if (stop_requested() || end_of_input_) return false;
  if (input_is_file_) return spin_file_once(timeout_ms);
  lcm::LCM& in = input();
  if (status_.state() == wingman::status_t::STATE_STARTING) status_.set_state(wingman::status_t::STATE_OK, "");
  {
    // Wait for LCM's descriptor or a wake(); then handle what is there without blocking again.
    pollfd fds[2] = {{in.getFileno(), POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    const int ready = poll(fds, 2, std::max(0, timeout_ms));
    if (ready < 0 && errno != EINTR)
      throw std::runtime_error(fmt::format("poll on the LCM input failed: {}", std::strerror(errno)));
    if (ready > 0 && (fds[1].revents & POLLIN) != 0) {
      uint64_t count = 0;
      [[maybe_unused]] const ssize_t n = read(wake_fd_, &count, sizeof count);
    }
    if (ready > 0 && fds[0].revents != 0 && !stop_requested()) {
      if (in.handleTimeout(0) < 0 && !stop_requested())
        throw std::runtime_error("LCM input failed while waiting for messages");
    }
  }
  heartbeat_if_due();
  return !(stop_requested() || end_of_input_);
}

int Runtime::drain(int max_messages) {
  g_starting.store(false);
  if (input_is_file_) return 0;
  int n = 0;
  lcm::LCM& in = input();
  while (n < max_messages && !stop_requested() && in.handleTimeout(0) > 0) ++n;
  return n;
}

int Runtime::spin() {
  while (spin_once(100)) {
  }
  return shutdown();
}

int Runtime::shutdown(const std::string& reason) {
  if (!reason.empty()) stop_reason_ = reason;
  if (stop_reason_.empty() && g_signal.load() != 0) stop_reason_ = fmt::format("signal {}", g_signal.load());
  if (stop_reason_.empty()) stop_reason_ = "requested";
  spdlog::info("stopping: {}", stop_reason_);
  status_.set_state(wingman::status_t::STATE_STOPPING, stop_reason_);
  publish_heartbeat();
  return 0;
}

int run_process_impl(const ProcessInfo& info, int argc, char** argv,
                     const std::function<std::string(const ConfigSources&, bool)>& load_config,
                     const std::function<int(Runtime&)>& body) {
  const std::string prog = info.executable;
  RuntimeOptions ro;
  CLI::App app{info.description, prog};
  app.add_option("--config", ro.config.files,
                 "YAML configuration file (default: built-in defaults; see config/" + info.name +
                     ".yaml); repeatable: files are read in order, a later file's keys win")
      ->allow_extra_args(false)
      ->type_name("FILE");
  app.add_option("--set", ro.config.sets,
                 "KEY=VALUE: one key over the --config files, VALUE a YAML scalar or sequence (e.g. "
                 "formation.offset_m=[-6,2,0]); repeatable, a later --set wins")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  app.add_flag("--print-config", ro.print_config, "Print the effective configuration as YAML and exit");
  app.set_version_flag("--version", prog + " " + version(), "Print the version (and the commit built from) and exit");
  app.add_option("--lcm-url", ro.lcm_url, "LCM URL for input and output (default: LCM_DEFAULT_URL or LCM's default)");
  app.add_option("--lcm-in", ro.lcm_in,
                 "LCM URL to read from, e.g. file:///tmp/in.lcmlog?speed=0 (default: --lcm-url)");
  app.add_option("--lcm-out", ro.lcm_out,
                 "LCM URL to publish to, e.g. file:///tmp/out.lcmlog?mode=w (default: --lcm-url)");
  app.add_option("--name", ro.instance,
                 "Instance name in status messages and the status channel (default: " + info.name + ")");
  app.add_flag("--lockstep", ro.lockstep,
               "Publish status after every handled message (for `wingman replay --lockstep`)");
  app.add_option("--status-period", ro.status_period_s, "Heartbeat period, seconds (default 1)");
  app.add_option("--log-level", ro.log_level, "trace, debug, info, warn or error (default info)");
  app.add_option("--watchdog", ro.watchdog_s,
                 "Exit 1 when the main loop makes no progress for this many seconds (default 0: off)");
  app.add_flag("--skip-corrupt-log", ro.skip_corrupt_log,
               "A corrupt event of a file:// input is skipped and counted (default: exit 1 naming its byte offset)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << prog << ": error: " << e.what() << " (see --help)" << std::endl;
    return 2;
  }

  auto logger = spdlog::stderr_color_st(info.name);
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %^%l%$: %v");
  spdlog::set_default_logger(logger);

  if (const std::string bad = ro.validate(); !bad.empty()) {
    std::cerr << prog << ": error: " << bad << std::endl;
    return 2;
  }
  spdlog::set_level(spdlog::level::from_str(ro.log_level));

  try {
    const std::string printed = load_config(ro.config, ro.print_config);
    if (ro.print_config) {
      std::cout << printed << std::flush;
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << prog << ": error: " << e.what() << std::endl;
    return 2;
  }

  try {
    Runtime rt(info, ro);
    spdlog::info("started (pid {}, instance '{}')", getpid(), rt.instance());
    const int rc = body(rt);
    return rc;
  } catch (const std::exception& e) {
    std::cerr << prog << ": error: " << e.what() << std::endl;
    return 1;
  }
}

}  // namespace wingman::common
