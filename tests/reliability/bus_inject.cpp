// SPDX-License-Identifier: MIT
// wingman-bus-inject: the survival test's hostile publisher (tests/reliability/supervisor_fault_test.sh). It waits
// for the next real message of one type on one channel of the live bus, copies it, makes the copy lie, publishes
// the copy once on the same channel and exits. Copies of real messages, so that only the lie is wrong:
//   --ahead-s S   every time in the copy moves S seconds later (utime; for targets_t also each target's
//                 source_utime and predicted_utime): a message dated in the future
//   --seq-jump N  image_t.seq / detections_t.seq of the copy is the original's + N (the hang-inducing jump)
// It prints one line on stdout when it has published:
//   <wall_us> INJECTED <channel> <type> <original utime> <copy utime> <copy seq, -1 if the type has none>
// Usage: wingman-bus-inject --lcm-url URL --channel CH --type image|detections|own_pose|targets
//                           [--ahead-s S] [--seq-jump N] [--timeout S]
// Exits 0 once published; 1 with one line if no message came within --timeout (default 10 s) or LCM cannot be
// opened; 2 on a bad command line.
#include <lcm/lcm-cpp.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/targets_t.hpp>

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace {

int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Lie {
  int64_t ahead_us = 0;
  int64_t seq_jump = 0;
};

// One function per type: applies the lie to the copy; returns the copy's seq (-1 if the type has none).
int64_t apply(wingman::image_t& m, const Lie& lie) {
  m.utime += lie.ahead_us;
  m.seq += lie.seq_jump;
  return m.seq;
}
int64_t apply(wingman::detections_t& m, const Lie& lie) {
  m.utime += lie.ahead_us;
  m.seq += lie.seq_jump;
  return m.seq;
}
int64_t apply(wingman::own_pose_t& m, const Lie& lie) {
  m.utime += lie.ahead_us;
  return -1;
}
int64_t apply(wingman::targets_t& m, const Lie& lie) {
  m.utime += lie.ahead_us;
  for (auto& t : m.targets) {
    t.source_utime += lie.ahead_us;
    t.predicted_utime += lie.ahead_us;
  }
  return -1;
}

template <class Msg>
struct Catcher {
  std::optional<Msg> caught;
  void on(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    if (caught) return;
    Msg m;
    if (m.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) >= 0) caught = std::move(m);
  }
};

template <class Msg>
int run(lcm::LCM& lcm, const std::string& channel, const std::string& type, const Lie& lie, double timeout_s) {
  Catcher<Msg> catcher;
  lcm::Subscription* sub = lcm.subscribe("^" + channel + "$", &Catcher<Msg>::on, &catcher);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!catcher.caught && std::chrono::steady_clock::now() < end) lcm.handleTimeout(50);
  lcm.unsubscribe(sub);
  if (!catcher.caught) {
    std::fprintf(stderr, "wingman-bus-inject: error: no %s message on %s within %g s\n", type.c_str(), channel.c_str(),
                 timeout_s);
    return 1;
  }
  Msg copy = *catcher.caught;
  const int64_t original_utime = copy.utime;
  const int64_t seq = apply(copy, lie);
  if (lcm.publish(channel, &copy) != 0) {
    std::fprintf(stderr, "wingman-bus-inject: error: publishing on %s failed\n", channel.c_str());
    return 1;
  }
  std::printf("%lld INJECTED %s %s %lld %lld %lld\n", static_cast<long long>(wall_us()), channel.c_str(), type.c_str(),
              static_cast<long long>(original_utime), static_cast<long long>(copy.utime), static_cast<long long>(seq));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string url, channel, type;
  double ahead_s = 0, timeout_s = 10;
  int64_t seq_jump = 0;
  CLI::App app{"Publishes one lying copy of the next real message on a channel", "wingman-bus-inject"};
  app.add_option("--lcm-url", url, "LCM URL")->required();
  app.add_option("--channel", channel, "channel to copy from and publish on")->required();
  app.add_option("--type", type, "message type: image, detections, own_pose or targets")->required();
  app.add_option("--ahead-s", ahead_s, "move every time in the copy this many seconds later");
  app.add_option("--seq-jump", seq_jump, "add this to the copy's seq (image, detections)");
  app.add_option("--timeout", timeout_s, "seconds to wait for the message to copy (default 10)");
  CLI11_PARSE(app, argc, argv);
  if (!std::isfinite(ahead_s) || std::fabs(ahead_s) > 1e9 || !(timeout_s > 0)) {
    std::fprintf(stderr, "wingman-bus-inject: error: --ahead-s must be finite (|S| <= 1e9), --timeout > 0\n");
    return 2;
  }
  if (seq_jump != 0 && type != "image" && type != "detections") {
    std::fprintf(stderr, "wingman-bus-inject: error: --seq-jump needs --type image or detections\n");
    return 2;
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "wingman-bus-inject: error: cannot open LCM '%s'\n", url.c_str());
    return 1;
  }
  const Lie lie{static_cast<int64_t>(std::llround(ahead_s * 1e6)), seq_jump};
  if (type == "image") return run<wingman::image_t>(lcm, channel, type, lie, timeout_s);
  if (type == "detections") return run<wingman::detections_t>(lcm, channel, type, lie, timeout_s);
  if (type == "own_pose") return run<wingman::own_pose_t>(lcm, channel, type, lie, timeout_s);
  if (type == "targets") return run<wingman::targets_t>(lcm, channel, type, lie, timeout_s);
  std::fprintf(stderr, "wingman-bus-inject: error: --type '%s': must be image, detections, own_pose or targets\n",
               type.c_str());
  return 2;
}
