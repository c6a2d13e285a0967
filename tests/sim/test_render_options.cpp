// SPDX-License-Identifier: MIT
// RenderOptions: valid defaults, validate() naming each bad key, the YAML loader reporting every problem at once.
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/sim/render_options.hpp>

namespace wingman::sim {
namespace {

using test::joined;

TEST(RenderOptions, DefaultsAreValid) {
  EXPECT_TRUE(RenderOptions{}.validate().empty()) << joined(RenderOptions{}.validate());
}

TEST(RenderOptions, ValidateNamesEveryBadKey) {
  RenderOptions o;
  o.supersampling = 0;
  o.max_half_fov_deg = 89.0;
  o.background = "stars";
  o.shading = "toon";
  o.sky_zenith_colour = {0.1, 0.2};
  o.sun_elevation_deg = 120.0;
  o.visibility_m = 0.0;
  o.noise_std = -1.0;
  o.motion_blur_samples = 1;
  o.exposure_drift_amplitude = 1.5;
  const std::string problems = joined(o.validate());
  for (const char* key : {"render.supersampling = 0", "render.max_half_fov_deg = 89", "render.background = 'stars'",
                          "render.shading = 'toon'", "render.sky_zenith_colour = '[0.1, 0.2]'",
                          "render.sun_elevation_deg = 120", "render.visibility_m = 0", "render.noise_std = -1",
                          "render.motion_blur_samples = 1", "render.exposure_drift_amplitude = 1.5"}) {
    EXPECT_NE(problems.find(key), std::string::npos) << key << " missing from:\n" << problems;
  }
}

TEST(RenderOptions, YamlLoaderReportsEveryBadKeyAtOnce) {
  const RenderOptions o = common::load_options_from_string<RenderOptions>(
      "render:\n  supersampling: 3\n  sky_zenith_colour: [10, 20, 200]\n  treeline: false\n", "r.yaml");
  EXPECT_EQ(o.supersampling, 3);
  EXPECT_FALSE(o.treeline);
  EXPECT_EQ(o.sky_zenith_colour, (std::vector<double>{10, 20, 200}));
  try {
    common::load_options_from_string<RenderOptions>("render:\n  supersampling: two\n  cloud_cover: 3\n  clouds: 0.5\n",
                                                    "r.yaml");
    FAIL() << "bad config accepted";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("r.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("render.supersampling"), std::string::npos) << what;
    EXPECT_NE(what.find("render.clouds"), std::string::npos) << what;
    EXPECT_NE(what.find("render.cloud_cover = 3"), std::string::npos) << what;
  }
}

TEST(RenderOptions, PrintedDefaultsReadBackEqual) {
  const std::string text = common::print_options(RenderOptions{});
  const RenderOptions back = common::load_options_from_string<RenderOptions>(text, "printed");
  EXPECT_EQ(common::print_options(back), text);
}

}  // namespace
}  // namespace wingman::sim
