#pragma once
// What the timing benchmarks share: the wall clock in milliseconds, the median of a stage's
// times, and FNV-1a over bytes for the checksums that show an optimization changed no output.

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace taiga::bench {

using Clock = std::chrono::steady_clock;

inline double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The median (the upper one of an even count); 0 for none.
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

inline constexpr std::uint64_t kFnvOffset = 0xcbf29ce484222325ULL;

/// FNV-1a over `size` bytes, continued from `hash`.
inline std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t hash = kFnvOffset) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
  return hash;
}

/// FNV-1a over the bytes of a vector's elements, continued from `hash`.
template <class T>
std::uint64_t fnv1a(const std::vector<T>& values, std::uint64_t hash) {
  return fnv1a(values.data(), values.size() * sizeof(T), hash);
}

}  // namespace taiga::bench
