// SPDX-License-Identifier: MIT
// BusWatch on a real LCM bus (udpm on loopback in a private network namespace): heartbeats, counts, bad messages,
// listening on the caller's LCM.
#include <gtest/gtest.h>
#include <wingman/launcher/bus_watch.hpp>

#include "../support/test_support.hpp"

#include <chrono>
#include <stdexcept>
#include <vector>

namespace wingman::launcher {
namespace {

status_t heartbeat(const std::string& process, int64_t handled) {
  status_t s{};
  s.process = process;
  s.state = status_t::STATE_OK;
  s.messages_handled = handled;
  s.last_processed_seq = -1;
  channel_stats_t c{};
  c.channel = "IMAGE_CAM0";
  c.direction = channel_stats_t::DIRECTION_IN;
  c.count = handled;
  s.channels.push_back(c);
  s.num_channels = 1;
  return s;
}

TEST(BusWatch, SeesHeartbeatsAndCountsTheChosenChannels) {
  const std::string url = wingman::testing::netns_lcm_url();
  BusWatch watch(url, "IMAGE_CAM0|DETECTIONS_CAM0");
  lcm::LCM pub(url);
  ASSERT_TRUE(pub.good());
  const std::vector<uint8_t> bytes(100, 7);
  // Published until seen (the first datagrams may go out before the watch listens: none is lost here, but bounded).
  const bool seen = watch.spin_until(
      [&] {
        const status_t hb = heartbeat("detector", 3);
        pub.publish("STATUS_DETECTOR", &hb);
        pub.publish("IMAGE_CAM0", bytes.data(), static_cast<unsigned>(bytes.size()));
        pub.publish("OTHER", bytes.data(), static_cast<unsigned>(bytes.size()));
        return watch.status("detector") != nullptr && watch.count("IMAGE_CAM0") >= 2;
      },
      10.0);
  ASSERT_TRUE(seen);
  EXPECT_EQ(watch.status("detector")->messages_handled, 3);
  EXPECT_EQ(channel_count(*watch.status("detector"), "IMAGE_CAM0", channel_stats_t::DIRECTION_IN), 3);
  EXPECT_EQ(channel_count(*watch.status("detector"), "IMAGE_CAM0", channel_stats_t::DIRECTION_OUT), 0);
  EXPECT_EQ(watch.count("OTHER"), 0);  // not chosen
  EXPECT_EQ(watch.count("DETECTIONS_CAM0"), 0);
  EXPECT_EQ(watch.status("localizer"), nullptr);

  // A heartbeat that does not decode is counted and changes nothing.
  pub.publish("STATUS_DETECTOR", bytes.data(), static_cast<unsigned>(bytes.size()));
  ASSERT_TRUE(watch.spin_until([&] { return watch.bad_messages() == 1; }, 10.0));
  EXPECT_EQ(watch.status("detector")->messages_handled, 3);
}

TEST(BusWatch, WaitingForHeartbeatsReturnsWhoIsMissing) {
  const std::string url = wingman::testing::netns_lcm_url();
  BusWatch watch(url);
  lcm::LCM pub(url);
  const status_t hb = heartbeat("localizer", 0);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> missing;
  for (int i = 0; i < 20 && (missing.empty() || missing.size() > 1); ++i) {
    pub.publish("STATUS_LOCALIZER", &hb);
    missing = watch.wait_for_status({"localizer", "follower_ctrl"}, 0.2);
  }
  EXPECT_EQ(missing, std::vector<std::string>{"follower_ctrl"});
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  // A stop request ends the wait at once.
  int asked = 0;
  missing = watch.wait_for_status({"follower_ctrl"}, 60.0, [&] { return ++asked > 1; });
  EXPECT_EQ(missing, std::vector<std::string>{"follower_ctrl"});
}

TEST(BusWatch, AHeartbeatThatFailsValidationIsCountedAndIgnored) {
  const std::string url = wingman::testing::netns_lcm_url();
  BusWatch watch(url);
  lcm::LCM pub(url);
  ASSERT_TRUE(pub.good());
  status_t bad = heartbeat("detector", 1);
  bad.state = 9;  // decodes, but no status_t state
  ASSERT_TRUE(watch.spin_until(
      [&] {
        pub.publish("STATUS_DETECTOR", &bad);
        return watch.bad_messages() >= 1;
      },
      10.0));
  EXPECT_EQ(watch.status("detector"), nullptr);
}

TEST(BusWatch, OnTheCallersLcmItsSpinsServeBothAndItUnsubscribesWhenDestroyed) {
  const std::string url = wingman::testing::netns_lcm_url();
  lcm::LCM lcm(url);
  lcm::LCM pub(url);
  ASSERT_TRUE(lcm.good() && pub.good());
  struct Counter {
    int64_t n = 0;
    void on(const lcm::ReceiveBuffer*, const std::string&) { ++n; }
  } other;
  lcm.subscribe("OTHER", &Counter::on, &other);
  const std::vector<uint8_t> bytes(10, 1);
  const status_t hb = heartbeat("localizer", 0);
  {
    BusWatch watch(lcm, "IMAGE_CAM0");
    std::vector<std::string> missing{"localizer"};
    for (int i = 0; i < 50 && (!missing.empty() || other.n == 0 || watch.count("IMAGE_CAM0") == 0); ++i) {
      pub.publish("STATUS_LOCALIZER", &hb);
      pub.publish("OTHER", bytes.data(), static_cast<unsigned>(bytes.size()));
      pub.publish("IMAGE_CAM0", bytes.data(), static_cast<unsigned>(bytes.size()));
      missing = watch.wait_for_status({"localizer"}, 0.2);
    }
    EXPECT_TRUE(missing.empty());
    EXPECT_GT(other.n, 0) << "the caller's subscription is handled by the watch's spins";
    EXPECT_GT(watch.count("IMAGE_CAM0"), 0);
    // The caller's own handle calls serve the watch too.
    const int64_t before = watch.count("IMAGE_CAM0");
    for (int i = 0; i < 50 && watch.count("IMAGE_CAM0") == before; ++i) {
      pub.publish("IMAGE_CAM0", bytes.data(), static_cast<unsigned>(bytes.size()));
      lcm.handleTimeout(100);
    }
    EXPECT_GT(watch.count("IMAGE_CAM0"), before);
  }
  // The watch is gone: the caller's LCM goes on without calling it (ASan would see a use after free).
  const int64_t before = other.n;
  for (int i = 0; i < 50 && other.n == before; ++i) {
    pub.publish("STATUS_LOCALIZER", &hb);
    pub.publish("IMAGE_CAM0", bytes.data(), static_cast<unsigned>(bytes.size()));
    pub.publish("OTHER", bytes.data(), static_cast<unsigned>(bytes.size()));
    lcm.handleTimeout(100);
  }
  EXPECT_GT(other.n, before);
}

TEST(BusWatch, AnUrlThatCannotBeOpenedIsAnErrorNamingIt) {
  try {
    BusWatch watch("nosuchprovider://x");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://x"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::launcher
