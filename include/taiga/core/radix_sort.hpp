#pragma once
// Sorting (key, value) pairs by a 64-bit key, for the voxel grids: their keys pack three cell
// indices into one integer, and over a scan or a local map most of its bytes are the same in
// every key. A least-significant-digit radix sort that skips those bytes takes two to five passes
// of 256 buckets, several times faster than a comparison sort of the pairs (perf, issue 26).
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace taiga {

/// Sorts `items` by `first` (a 64-bit integer) ascending. Stable, so with distinct keys the order
/// is the one any sort gives.
template <class Key, class Value>
void radixSortByKey(std::vector<std::pair<Key, Value>>& items) {
  static_assert(std::is_integral_v<Key> && sizeof(Key) == 8);
  if (items.size() < 2) return;
  // Signed keys with the sign bit flipped sort as unsigned ones.
  constexpr std::uint64_t kFlip = std::is_signed_v<Key> ? std::uint64_t{1} << 63 : 0;
  auto bits = [](Key key) { return static_cast<std::uint64_t>(key) ^ kFlip; };
  std::uint64_t all_or = 0, all_and = ~std::uint64_t{0};
  for (const auto& item : items) {
    all_or |= bits(item.first);
    all_and &= bits(item.first);
  }
  const std::uint64_t varying = all_or ^ all_and;  // bits that differ between some two keys
  std::vector<std::pair<Key, Value>> buffer(items.size());
  for (int shift = 0; shift < 64; shift += 8) {
    if (((varying >> shift) & 0xFF) == 0) continue;  // every key has this byte: order kept
    std::array<std::size_t, 256> start{};
    for (const auto& item : items) ++start[(bits(item.first) >> shift) & 0xFF];
    std::size_t sum = 0;
    for (std::size_t& s : start) sum += std::exchange(s, sum);
    for (auto& item : items) buffer[start[(bits(item.first) >> shift) & 0xFF]++] = std::move(item);
    items.swap(buffer);
  }
}

}  // namespace taiga
