// SPDX-License-Identifier: MIT
// A small seeded random source whose sequence is the same on every platform and standard library.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace wingman::training {

/// std::mt19937_64 (its sequence is fixed by the C++ standard) with our own uniform and normal draws
/// (std's distributions differ between standard libraries), so a seed gives the same augmentation and
/// data order everywhere.
class SeededRandom {
 public:
  explicit SeededRandom(uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// True with probability p.
  bool chance(double p) { return uniform() < p; }
  /// Uniform integer in 0 .. n - 1 (n >= 1), without modulo bias worth mentioning for n << 2^64.
  uint64_t below(uint64_t n) { return engine_() % n; }
  /// Standard normal (Box-Muller).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  /// Darknet's rand_scale(s): a factor uniform in [1, s], inverted with probability 1/2 (s >= 1).
  double scale_factor(double s) {
    const double f = uniform(1.0, s);
    return chance(0.5) ? f : 1.0 / f;
  }
  /// A raw 64-bit value.
  uint64_t next() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

/// Mixes a base seed with up to two indices into one seed (splitmix64 finaliser), so sample k of
/// iteration i gets its own stream independent of how many samples were drawn before.
inline uint64_t mix_seed(uint64_t seed, uint64_t a, uint64_t b = 0) {
  uint64_t z = seed ^ (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xC2B2AE3D27D4EB4Full);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace wingman::training
