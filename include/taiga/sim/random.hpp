#pragma once
// Random numbers that are the same on every platform and for every thread count.
//
// The standard library's distributions (std::normal_distribution, ...) are implementation-defined,
// so the simulator draws from std::mt19937_64 (whose sequence the standard fixes) through the
// distributions below. Per-pixel and per-sample noise that is computed in parallel uses a
// counter-based generator instead (hashUniform/hashNormal): the value depends only on the seed and
// the indices, never on which thread computes it or in which order.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string_view>

namespace taiga::sim {

/// SplitMix64 finalizer: a bijective, well-mixed hash of a 64-bit value.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// A seed for one named stream of random numbers derived from the user's seed, so that adding
/// draws to one part of the simulator does not change the others.
constexpr std::uint64_t streamSeed(std::uint64_t seed, std::string_view stream) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a of the stream name
  for (const char c : stream) h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return mix64(seed ^ mix64(h));
}

/// Uniform in [0, 1) with 53 random bits.
constexpr double toUnit(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// Uniform in [0, 1) from a seed and up to three indices (counter-based).
constexpr double hashUniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0,
                             std::uint64_t c = 0) {
  return toUnit(mix64(mix64(mix64(seed ^ mix64(a)) ^ b) ^ (c * 0xD1B54A32D192ED03ull)));
}

/// Standard normal from a seed and indices (Box-Muller on two counter-based uniforms).
inline double hashNormal(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0,
                         std::uint64_t c = 0) {
  const double u1 = 1.0 - hashUniform(seed, a, b, 2 * c);  // (0, 1]
  const double u2 = hashUniform(seed, a, b, 2 * c + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// Sequential generator with portable distributions.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1).
  double unit() { return toUnit(engine_()); }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  /// Integer uniform in [lo, hi] (tiny modulo bias is irrelevant here).
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  /// Standard normal (Box-Muller; the second value is discarded for simplicity).
  double normal() {
    const double u1 = 1.0 - unit();
    const double u2 = unit();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// True with probability p.
  bool bernoulli(double p) { return unit() < p; }
  std::uint64_t bits() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace taiga::sim
