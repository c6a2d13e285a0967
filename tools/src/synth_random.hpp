// SPDX-License-Identifier: MIT
// The random draws `wingman dataset synth` and `wingman scenario random` share: a portable generator, scenes,
// airframes.
#pragma once

#include "wingman/tools/dataset_synth.hpp"

#include <wingman/sim/drone_spec.hpp>
#include <wingman/sim/render_options.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace wingman::tools {

constexpr double kSynthPi = 3.14159265358979323846;
constexpr double kSynthDeg = kSynthPi / 180.0;  // radians per degree

// A small counter-based generator (splitmix64): the same numbers on every platform and standard library, so a seed
// gives the same dataset everywhere.
class SynthRandom {
 public:
  explicit SynthRandom(uint64_t seed) : state_(seed) {}
  SynthRandom(uint64_t seed, uint64_t stream, uint64_t index) : state_(mix(mix(seed ^ mix(stream)) ^ mix(index + 1))) {}
  uint64_t next() { return mix(state_ += 0x9E3779B97F4A7C15ull); }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  ///< [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
  bool chance(double p) { return uniform() < p; }
  size_t index(size_t n) { return static_cast<size_t>(uniform() * static_cast<double>(n)) % n; }
  double normal() {  ///< standard normal (Box-Muller)
    const double u1 = (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kSynthPi * uniform());
  }
  Eigen::Vector3d direction() {  ///< uniform on the unit sphere
    const double z = uniform(-1.0, 1.0), a = uniform(0.0, 2.0 * kSynthPi), r = std::sqrt(1.0 - z * z);
    return {r * std::cos(a), r * std::sin(a), z};
  }

 private:
  static uint64_t mix(uint64_t x) {
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  uint64_t state_;
};

/// The scene, light and sensor of one image, drawn around `c.render` within the ranges of `c` (sky and cloud colours,
/// sun, ground, treeline, haze, exposure, noise, motion blur).
sim::RenderOptions random_scene(const DatasetSynthConfig& c, SynthRandom& rng);

/// A random procedural multirotor (size scaled within [c.scale_min, c.scale_max] of the F450-like default, colours,
/// propellers, landing gear). `frame` quad, hex or octo fixes the arm count; "" draws it (60 % quad, 25 % hex,
/// 15 % octo). The same draws are made either way, so a given frame does not shift the other numbers.
sim::DroneSpec random_airframe(const DatasetSynthConfig& c, SynthRandom& rng, const std::string& frame = "");

}  // namespace wingman::tools
