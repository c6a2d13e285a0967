// SPDX-License-Identifier: MIT
// Options of the simulator's camera renderer (keys under "render."): scene, lighting, sensor effects, quality.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::sim {

/// What the renderer draws and how. World frame ENU (x east, y north, z up), metres; angles in degrees; colours are
/// display (sRGB) triples in 0..1 (or all three in 0..255). The defaults give a plausible summer daylight image:
/// blue sky fading to a hazy horizon, scattered clouds, sun at 40 degrees, grass fields and a treeline.
struct RenderOptions {
  // ---- quality ----
  /// Supersampling per axis, 1..4: the scene is rendered at this many times the camera's pixel density and each
  /// output pixel averages supersampling^2 samples (through the lens distortion).
  int supersampling = 2;
  /// The sky, ground and treeline are computed once per n x n block of pixels and interpolated, 1..4 (2: four times
  /// cheaper; the horizon and the treeline's top soften over n pixels). Drones are always at full resolution.
  int background_subsampling = 2;
  /// Largest angle off the optical axis that is rendered, degrees, 10..85 (the intermediate pinhole image must
  /// cover the whole camera; fisheye pixels beyond this angle come out black).
  double max_half_fov_deg = 80.0;
  /// Scene seed: cloud pattern, ground texture and treeline shape (per-frame noise is seeded by render()'s
  /// frame_seed).
  int64_t seed = 1;

  // ---- scene ----
  /// scene (sky, clouds, ground, treeline) or uniform (background_colour everywhere: masks and pixel tests).
  std::string background = "scene";
  std::vector<double> background_colour = {0.5, 0.5, 0.5};     ///< background uniform: its colour, sRGB
  std::vector<double> sky_zenith_colour = {0.25, 0.45, 0.8};   ///< sky straight up, sRGB
  std::vector<double> sky_horizon_colour = {0.75, 0.82, 0.9};  ///< sky at the horizon, sRGB
  double cloud_cover = 0.4;                                    ///< fraction of the sky covered by clouds, 0..1
  double cloud_altitude_m = 1500.0;                            ///< cloud layer height above the ground, metres
  double cloud_scale_m = 800.0;                                ///< typical cloud size, metres
  std::vector<double> cloud_colour = {0.95, 0.95, 0.97};       ///< lit cloud colour, sRGB
  double sun_azimuth_deg = 135.0;   ///< sun bearing, degrees clockwise from north (+y) towards east (+x)
  double sun_elevation_deg = 40.0;  ///< sun elevation above the horizon, degrees, -10..90
  double sun_intensity = 1.0;       ///< direct sunlight scale, >= 0 (0: overcast, ambient light only)
  double ambient_intensity = 0.45;  ///< sky (ambient) light scale, >= 0
  bool ground = true;               ///< draw the ground plane z = 0 (else sky below the horizon too)
  std::vector<double> ground_colour_a = {0.30, 0.42, 0.18};  ///< grass, sRGB
  std::vector<double> ground_colour_b = {0.45, 0.40, 0.28};  ///< dry field / soil, sRGB
  double ground_texture_scale_m = 40.0;                      ///< size of fields and patches on the ground, metres
  bool treeline = true;                                      ///< draw a belt of forest and hills around the camera
  double treeline_distance_m = 350.0;  ///< horizontal distance of the treeline from the camera, metres
  double treeline_height_m = 18.0;     ///< mean tree height, metres
  double treeline_depth_m = 150.0;     ///< depth of the belt of forest beyond treeline_distance_m, metres
  std::vector<double> treeline_colour = {0.12, 0.2, 0.1};  ///< trees, sRGB
  double visibility_m = 8000.0;                            ///< distance at which haze hides the ground (fog), metres
  /// lit (sun, sky ambient, a little specular) or flat (each surface at its own colour, unlit: pixel tests).
  std::string shading = "lit";

  // ---- sensor ----
  double exposure_gain = 1.0;  ///< brightness multiplier before the sensor's clipping, > 0
  /// Per-frame random exposure change: the gain is multiplied by exp(N(0, exposure_jitter^2)) drawn from the
  /// frame seed (0: off).
  double exposure_jitter = 0.0;
  double exposure_drift_amplitude = 0.0;  ///< slow auto-exposure drift: gain *= 1 + a sin(2 pi t / period), 0..0.9
  double exposure_drift_period_s = 20.0;  ///< drift period, seconds, > 0
  double noise_std = 1.5;                 ///< read noise, standard deviation in 8-bit levels (0: off)
  double shot_noise = 0.3;                ///< photon noise: variance = shot_noise * level (8-bit levels; 0: off)
  /// Motion blur: shutter time, seconds (0: off). The frame is the mean of motion_blur_samples renderings over
  /// [utime - exposure/2, utime + exposure/2], with the drones and the camera moving at their velocities and
  /// the propellers turning at their rates.
  double motion_blur_exposure_s = 0.0;
  int motion_blur_samples = 8;  ///< renderings averaged for motion blur, 2..64

  template <class V>
  void visit(V& v) {
    v("render.supersampling", supersampling, "samples per pixel per axis, 1..4 (antialiasing)");
    v("render.background_subsampling", background_subsampling,
      "sky/ground/trees computed per n x n pixels and interpolated, 1..4 (drones always at full resolution)");
    v("render.max_half_fov_deg", max_half_fov_deg, "largest angle off the optical axis rendered, degrees (10..85)");
    v("render.seed", seed, "scene seed: clouds, ground texture, treeline");
    v("render.background", background, "scene (sky, clouds, ground, trees) or uniform (background_colour)");
    v("render.background_colour", background_colour, "background uniform: colour, sRGB [r, g, b]");
    v("render.sky_zenith_colour", sky_zenith_colour, "sky colour straight up, sRGB");
    v("render.sky_horizon_colour", sky_horizon_colour, "sky colour at the horizon, sRGB");
    v("render.cloud_cover", cloud_cover, "fraction of the sky covered by clouds, 0..1");
    v("render.cloud_altitude_m", cloud_altitude_m, "cloud layer height, metres");
    v("render.cloud_scale_m", cloud_scale_m, "typical cloud size, metres");
    v("render.cloud_colour", cloud_colour, "lit cloud colour, sRGB");
    v("render.sun_azimuth_deg", sun_azimuth_deg, "sun bearing, degrees clockwise from north");
    v("render.sun_elevation_deg", sun_elevation_deg, "sun elevation, degrees (-10..90)");
    v("render.sun_intensity", sun_intensity, "direct sunlight scale (0 = overcast)");
    v("render.ambient_intensity", ambient_intensity, "sky light scale");
    v("render.ground", ground, "draw the ground plane z = 0");
    v("render.ground_colour_a", ground_colour_a, "ground colour 1 (grass), sRGB");
    v("render.ground_colour_b", ground_colour_b, "ground colour 2 (fields, soil), sRGB");
    v("render.ground_texture_scale_m", ground_texture_scale_m, "size of ground patches, metres");
    v("render.treeline", treeline, "draw trees and hills around the horizon");
    v("render.treeline_distance_m", treeline_distance_m, "treeline distance from the camera, metres");
    v("render.treeline_height_m", treeline_height_m, "mean tree height, metres");
    v("render.treeline_depth_m", treeline_depth_m, "depth of the forest belt, metres");
    v("render.treeline_colour", treeline_colour, "tree colour, sRGB");
    v("render.visibility_m", visibility_m, "haze: distance at which the ground fades into the horizon, metres");
    v("render.shading", shading, "lit (sun and sky light) or flat (unlit surface colours)");
    v("render.exposure_gain", exposure_gain, "brightness multiplier (> 0)");
    v("render.exposure_jitter", exposure_jitter, "per-frame random exposure change, log-normal sigma (0 = off)");
    v("render.exposure_drift_amplitude", exposure_drift_amplitude, "slow exposure drift amplitude, 0..0.9");
    v("render.exposure_drift_period_s", exposure_drift_period_s, "slow exposure drift period, seconds");
    v("render.noise_std", noise_std, "sensor read noise, 8-bit levels (0 = off)");
    v("render.shot_noise", shot_noise, "sensor photon noise, variance per 8-bit level (0 = off)");
    v("render.motion_blur_exposure_s", motion_blur_exposure_s, "shutter time for motion blur, seconds (0 = off)");
    v("render.motion_blur_samples", motion_blur_samples, "renderings averaged for motion blur, 2..64");
  }

  /// Every problem, as "render.key = value: rule" (empty when valid).
  std::vector<std::string> validate() const;
};

}  // namespace wingman::sim
