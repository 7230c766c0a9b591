#pragma once
// Sorting (key, value) pairs by a 64-bit key, for the voxel grids: their keys pack three cell
// indices into one integer, and over a scan or a local map most of its bytes are the same in
// every key. A least-significant-digit radix sort that skips those bytes takes two to five passes
// of 256 buckets, several times faster than a comparison sort of the pairs (perf, issue 26).
#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
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

/// Sorts `items` by keys that pack three 21-bit fields (x in bits 42-62, y in 21-41, z in 0-20:
/// the voxel keys), in the same order as radixSortByKey, with passes over only the bits that the
/// fields' ranges span. The fields are biased by 2^20, so a grid around its frame's origin has
/// cells on either side of 0x100000 in every field and keys that differ in all eight bytes:
/// radixSortByKey took eight passes over a local map's keys, this three or four.
template <class Key, class Value>
void radixSortByVoxelKey(std::vector<std::pair<Key, Value>>& items) {
  static_assert(std::is_integral_v<Key> && sizeof(Key) == 8);
  if (items.size() < 2) return;
  if (items.size() > std::numeric_limits<std::uint32_t>::max()) return radixSortByKey(items);
  constexpr std::uint64_t kField = (std::uint64_t{1} << 21) - 1;
  auto field = [](Key key, int axis) {
    return (static_cast<std::uint64_t>(key) >> (42 - 21 * axis)) & kField;
  };
  std::uint64_t low[3] = {kField, kField, kField}, high[3] = {0, 0, 0};
  for (const auto& item : items) {
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = std::min(low[axis], field(item.first, axis));
      high[axis] = std::max(high[axis], field(item.first, axis));
    }
  }
  int width[3];
  for (int axis = 0; axis < 3; ++axis) width[axis] = std::bit_width(high[axis] - low[axis]);
  // The fields minus their lowest values, packed tightly in the same order: the same order of keys.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order(items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Key key = items[i].first;
    const std::uint64_t compact =
        (((field(key, 0) - low[0]) << width[1] | (field(key, 1) - low[1])) << width[2]) |
        (field(key, 2) - low[2]);
    order[i] = {compact, static_cast<std::uint32_t>(i)};
  }
  radixSortByKey(order);
  std::vector<std::pair<Key, Value>> sorted;
  sorted.reserve(items.size());
  for (const auto& [compact, index] : order) sorted.push_back(std::move(items[index]));
  items.swap(sorted);
}

}  // namespace taiga
