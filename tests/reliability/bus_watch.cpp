// SPDX-License-Identifier: MIT
// wingman-bus-watch: prints one line per message on the channels the supervision fault test watches, so a shell
// script can follow the pipeline live. Each line starts with the receive wall-clock time (only for the test's
// restart bound) followed by fields of the message itself (message time for everything deterministic):
//   <recv_wall_us> TARGETS <utime> <num_targets> <newest target source_utime, 0 if none>
//   <recv_wall_us> DETECTIONS <channel> <utime> <seq> <num_detections>
//   <recv_wall_us> SETPOINT <utime> <mode>
//   <recv_wall_us> IMAGE <channel> <utime> <seq>
//   <recv_wall_us> STATUS <channel> <pid> <state> <drops_total> <detail>
//   <recv_wall_us> INPUT <status channel> <pid> <input channel> <count> <drops>   (one per input of the heartbeat)
//   <recv_wall_us> LASTERR <status channel> <pid> <last_error>                    (when it is not empty)
// Usage: wingman-bus-watch --lcm-url URL [--targets CH] [--detections CH] [--setpoint CH] [--image CH]... --seconds S
// Exits 0 after --seconds of wall time or on SIGTERM/SIGINT; 1 with one line if the LCM URL cannot be opened.
#include <lcm/lcm-cpp.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// Decodes one message; false (and a line on stderr naming the channel) if it does not decode.
template <class Msg>
bool decode(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Msg& msg) {
  if (msg.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0) {
    std::fprintf(stderr, "wingman-bus-watch: channel %s: %u bytes do not decode\n", channel.c_str(), rbuf->data_size);
    return false;
  }
  return true;
}

struct Printer {
  void targets(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    wingman::targets_t m;
    if (!decode(rbuf, ch, m)) return;
    int64_t newest = 0;
    for (const auto& t : m.targets) newest = std::max(newest, t.source_utime);
    std::printf("%lld TARGETS %lld %d %lld\n", static_cast<long long>(wall_us()), static_cast<long long>(m.utime),
                m.num_targets, static_cast<long long>(newest));
  }
  void detections(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    wingman::detections_t m;
    if (!decode(rbuf, ch, m)) return;
    std::printf("%lld DETECTIONS %s %lld %lld %d\n", static_cast<long long>(wall_us()), ch.c_str(),
                static_cast<long long>(m.utime), static_cast<long long>(m.seq), m.num_detections);
  }
  void setpoint(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    wingman::setpoint_t m;
    if (!decode(rbuf, ch, m)) return;
    std::printf("%lld SETPOINT %lld %d\n", static_cast<long long>(wall_us()), static_cast<long long>(m.utime), m.mode);
  }
  void image(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    wingman::image_t m;
    if (!decode(rbuf, ch, m)) return;
    std::printf("%lld IMAGE %s %lld %lld\n", static_cast<long long>(wall_us()), ch.c_str(),
                static_cast<long long>(m.utime), static_cast<long long>(m.seq));
  }
  void status(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
    wingman::status_t m;
    if (!decode(rbuf, ch, m)) return;
    std::string detail = m.detail;
    std::replace(detail.begin(), detail.end(), '\n', ' ');
    const long long now = static_cast<long long>(wall_us());
    std::printf("%lld STATUS %s %d %d %lld %s\n", now, ch.c_str(), m.pid, m.state,
                static_cast<long long>(m.drops_total), detail.c_str());
    for (const auto& c : m.channels) {
      if (c.direction != wingman::channel_stats_t::DIRECTION_IN) continue;
      std::printf("%lld INPUT %s %d %s %lld %lld\n", now, ch.c_str(), m.pid, c.channel.c_str(),
                  static_cast<long long>(c.count), static_cast<long long>(c.drops));
    }
    if (!m.last_error.empty()) {
      std::string error = m.last_error;
      std::replace(error.begin(), error.end(), '\n', ' ');
      std::printf("%lld LASTERR %s %d %s\n", now, ch.c_str(), m.pid, error.c_str());
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string url, targets = "TARGETS", detections = "DETECTIONS_CAM0", setpoint = "SETPOINT";
  std::vector<std::string> images;
  double seconds = 0;
  CLI::App app{"Prints the messages the supervision fault test watches, one line each", "wingman-bus-watch"};
  app.add_option("--lcm-url", url, "LCM URL")->required();
  app.add_option("--targets", targets, "targets_t channel (default TARGETS)");
  app.add_option("--detections", detections, "detections_t channel (default DETECTIONS_CAM0)");
  app.add_option("--setpoint", setpoint, "setpoint_t channel (default SETPOINT)");
  app.add_option("--image", images, "image_t channel(s) to watch (none by default)");
  app.add_option("--seconds", seconds, "exit after this many seconds of wall time (> 0)")->required();
  CLI11_PARSE(app, argc, argv);
  if (!(seconds > 0)) {
    std::fprintf(stderr, "wingman-bus-watch: error: --seconds = %g: must be > 0\n", seconds);
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // one line at a time: the test reads the file while it grows
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "wingman-bus-watch: error: cannot open LCM '%s'\n", url.c_str());
    return 1;
  }
  Printer p;
  lcm.subscribe("^" + targets + "$", &Printer::targets, &p);
  lcm.subscribe("^" + detections + "$", &Printer::detections, &p);
  lcm.subscribe("^" + setpoint + "$", &Printer::setpoint, &p);
  for (const auto& ch : images) lcm.subscribe("^" + ch + "$", &Printer::image, &p);
  lcm.subscribe("^STATUS_.*", &Printer::status, &p);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!g_stop.load() && std::chrono::steady_clock::now() < end) lcm.handleTimeout(100);
  return 0;
}
