// SPDX-License-Identifier: MIT
// Validation of RenderOptions.
#include "wingman/sim/render_options.hpp"

#include "colour.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>

#include <cmath>

namespace wingman::sim {

std::vector<std::string> RenderOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  const auto range = [&](const char* key, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi)) p.push_back(problem(key, value, fmt::format("must be in [{}, {}]", lo, hi)));
  };
  const auto positive = [&](const char* key, double value) {
    if (!(value > 0.0 && std::isfinite(value))) p.push_back(problem(key, value, "must be > 0"));
  };
  if (supersampling < 1 || supersampling > 4)
    p.push_back(problem("render.supersampling", supersampling, "must be in 1..4"));
  if (background_subsampling < 1 || background_subsampling > 4) {
    p.push_back(problem("render.background_subsampling", background_subsampling, "must be in 1..4"));
  }
  range("render.max_half_fov_deg", max_half_fov_deg, 10.0, 85.0);
  if (background != "scene" && background != "uniform") {
    p.push_back(problem("render.background", background, "must be scene or uniform"));
  }
  if (shading != "lit" && shading != "flat") p.push_back(problem("render.shading", shading, "must be lit or flat"));
  detail::check_colour_key("render.background_colour", background_colour, p);
  detail::check_colour_key("render.sky_zenith_colour", sky_zenith_colour, p);
  detail::check_colour_key("render.sky_horizon_colour", sky_horizon_colour, p);
  detail::check_colour_key("render.cloud_colour", cloud_colour, p);
  detail::check_colour_key("render.ground_colour_a", ground_colour_a, p);
  detail::check_colour_key("render.ground_colour_b", ground_colour_b, p);
  detail::check_colour_key("render.treeline_colour", treeline_colour, p);
  range("render.cloud_cover", cloud_cover, 0.0, 1.0);
  range("render.cloud_altitude_m", cloud_altitude_m, 100.0, 20000.0);
  range("render.cloud_scale_m", cloud_scale_m, 10.0, 100000.0);
  range("render.sun_azimuth_deg", sun_azimuth_deg, -360.0, 360.0);
  range("render.sun_elevation_deg", sun_elevation_deg, -10.0, 90.0);
  range("render.sun_intensity", sun_intensity, 0.0, 10.0);
  range("render.ambient_intensity", ambient_intensity, 0.0, 10.0);
  range("render.ground_texture_scale_m", ground_texture_scale_m, 0.1, 10000.0);
  range("render.treeline_distance_m", treeline_distance_m, 10.0, 100000.0);
  range("render.treeline_height_m", treeline_height_m, 0.0, 1000.0);
  range("render.treeline_depth_m", treeline_depth_m, 1.0, 100000.0);
  positive("render.visibility_m", visibility_m);
  range("render.exposure_gain", exposure_gain, 1e-3, 1e3);
  range("render.exposure_jitter", exposure_jitter, 0.0, 2.0);
  range("render.exposure_drift_amplitude", exposure_drift_amplitude, 0.0, 0.9);
  positive("render.exposure_drift_period_s", exposure_drift_period_s);
  range("render.noise_std", noise_std, 0.0, 100.0);
  range("render.shot_noise", shot_noise, 0.0, 100.0);
  range("render.motion_blur_exposure_s", motion_blur_exposure_s, 0.0, 1.0);
  if (motion_blur_samples < 2 || motion_blur_samples > 64) {
    p.push_back(problem("render.motion_blur_samples", motion_blur_samples, "must be in 2..64"));
  }
  return p;
}

}  // namespace wingman::sim
