// SPDX-License-Identifier: MIT
// BridgeOptions: defaults, the shipped config file, and problems named by key.
#include "test_support.hpp"

#include <wingman/common/config.hpp>
#include <wingman/mavlink_bridge/bridge_options.hpp>

#include <gtest/gtest.h>

using wingman::mavlink_bridge::BridgeOptions;

TEST(BridgeOptions, DefaultsAreValidAndTheShippedConfigIsTheDefaults) {
  EXPECT_TRUE(BridgeOptions{}.validate().empty());
  const auto loaded =
      wingman::common::load_options<BridgeOptions>(wingman::testing::source_path("config/mavlink_bridge.yaml"));
  EXPECT_EQ(wingman::common::print_options(loaded), wingman::common::print_options(BridgeOptions{}));
}

TEST(BridgeOptions, EveryBadValueIsNamedAtOnce) {
  const std::string yaml =
      "link: {url: 'tcp://x', system_id: 0}\n"
      "stream: {rate_hz: 1}\n"
      "limits: {min_altitude_m: 10, max_altitude_m: 5}\n"
      "autopilot: {kind: inav}\n";
  try {
    wingman::common::load_options_from_string<BridgeOptions>(yaml, "b.yaml");
    FAIL() << "expected a ConfigError";
  } catch (const wingman::common::ConfigError& e) {
    const std::string what = e.what();
    for (const char* key : {"link.url", "link.system_id", "stream.rate_hz", "limits.max_altitude_m", "autopilot.kind"})
      EXPECT_NE(what.find(key), std::string::npos) << key << " not in: " << what;
  }
}

TEST(BridgeOptions, ABaudRateTermiosLacksIsRefused) {
  BridgeOptions o;
  o.link_url = "/dev/ttyACM0";
  o.baud = 12345;
  ASSERT_EQ(o.validate().size(), 1u);
  EXPECT_NE(o.validate()[0].find("link.baud = 12345"), std::string::npos);
}
