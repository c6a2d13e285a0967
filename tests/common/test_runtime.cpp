// SPDX-License-Identifier: MIT
// Runtime: spin_once() handles a message as soon as it is there, and wake() from another thread ends its wait
// early (the real-time detector's worker hands results back this way). LCM's in-process memq:// transport.
#include "wingman/common/runtime.hpp"

#include <gtest/gtest.h>
#include <wingman/own_pose_t.hpp>

#include <chrono>
#include <thread>

namespace {

using namespace wingman;
using Clock = std::chrono::steady_clock;

common::RuntimeOptions memq_options() {
  common::RuntimeOptions ro;
  ro.lcm_url = "memq://";
  ro.status_period_s = 60.0;  // no heartbeat in the way
  return ro;
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

TEST(Runtime, SpinOnceHandlesAWaitingMessage) {
  common::Runtime rt({"runtime_test", "runtime-test", "test"}, memq_options());
  int handled = 0;
  rt.subscribe<own_pose_t>("OWN_POSE", [&](const own_pose_t&) { ++handled; });
  own_pose_t pose{};
  pose.utime = 1700000000000000;
  pose.frame = own_pose_t::FRAME_ENU;
  pose.q_body_to_world[0] = 1.0;
  rt.publish("OWN_POSE", pose);
  const auto t0 = Clock::now();
  EXPECT_TRUE(rt.spin_once(20000));
  EXPECT_EQ(handled, 1) << rt.status().last_error();
  EXPECT_LT(seconds_since(t0), 10.0) << "spin_once waited for its timeout with a message there";
  EXPECT_EQ(rt.status().messages_handled(), 1);
}

TEST(Runtime, WakeFromAnotherThreadEndsTheWaitEarly) {
  common::Runtime rt({"runtime_test", "runtime-test", "test"}, memq_options());
  rt.subscribe<own_pose_t>("OWN_POSE", [](const own_pose_t&) {});
  std::thread waker([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    rt.wake();
  });
  const auto t0 = Clock::now();
  EXPECT_TRUE(rt.spin_once(20000));
  const double waited_s = seconds_since(t0);
  waker.join();
  EXPECT_LT(waited_s, 10.0) << "wake() did not end the 20 s wait";
  EXPECT_EQ(rt.status().messages_handled(), 0);
}

TEST(Runtime, AWakeBeforeTheWaitIsKeptForIt) {
  common::Runtime rt({"runtime_test", "runtime-test", "test"}, memq_options());
  rt.subscribe<own_pose_t>("OWN_POSE", [](const own_pose_t&) {});
  rt.wake();
  rt.wake();  // wake-ups do not pile up: one wait ends, the next one waits again
  auto t0 = Clock::now();
  EXPECT_TRUE(rt.spin_once(20000));
  EXPECT_LT(seconds_since(t0), 10.0);
  t0 = Clock::now();
  EXPECT_TRUE(rt.spin_once(200));
  EXPECT_GE(seconds_since(t0), 0.15) << "a second wait ended without a wake-up";
}

}  // namespace
