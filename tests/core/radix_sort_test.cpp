#include "taiga/core/radix_sort.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace taiga {
namespace {

template <class Key>
void expectSameOrderAsAStableSort(std::vector<std::pair<Key, int>> items, bool voxel_keys = false) {
  std::vector<std::pair<Key, int>> expected = items;
  std::stable_sort(expected.begin(), expected.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  if (voxel_keys) {
    radixSortByVoxelKey(items);
  } else {
    radixSortByKey(items);
  }
  EXPECT_EQ(items, expected);
}

TEST(RadixSort, SortsUnsignedKeysThatDifferInAnyByte) {
  std::mt19937_64 rng(1);
  std::vector<std::pair<std::uint64_t, int>> items;
  for (int i = 0; i < 5000; ++i) items.emplace_back(rng(), i);
  expectSameOrderAsAStableSort(items);
}

TEST(RadixSort, SortsSignedKeysNegativeOnesFirst) {
  std::mt19937_64 rng(2);
  std::vector<std::pair<std::int64_t, int>> items;
  for (int i = 0; i < 5000; ++i)
    items.emplace_back(static_cast<std::int64_t>(rng() % 2001) - 1000, i);  // many equal keys
  expectSameOrderAsAStableSort(items);
}

TEST(RadixSort, SortsPackedVoxelKeysWhoseHighBytesAgree) {
  // Three 21-bit cell indices near the middle of their range, as a scan's voxels pack them.
  std::mt19937_64 rng(3);
  std::vector<std::pair<std::uint64_t, int>> items;
  for (int i = 0; i < 3000; ++i) {
    const std::uint64_t x = (1u << 20) + rng() % 300, y = (1u << 20) - rng() % 300,
                        z = (1u << 20) + rng() % 80;
    items.emplace_back((x << 42) | (y << 21) | z, i);
  }
  expectSameOrderAsAStableSort(items);
}

TEST(RadixSort, SortsVoxelKeysAroundTheOriginAsAnySortDoes) {
  // Cells on either side of the origin in every axis (each field either side of 2^20), as signed
  // and as unsigned keys, with some keys repeated (kept in input order).
  std::mt19937_64 rng(4);
  std::vector<std::pair<std::int64_t, int>> signed_items;
  std::vector<std::pair<std::uint64_t, int>> unsigned_items;
  for (int i = 0; i < 4000; ++i) {
    const std::uint64_t x = (1u << 20) + rng() % 600 - 300, y = (1u << 20) + rng() % 600 - 300,
                        z = (1u << 20) + rng() % 100 - 50;
    const std::uint64_t key = (x << 42) | (y << 21) | z;
    signed_items.emplace_back(static_cast<std::int64_t>(key), i);
    unsigned_items.emplace_back(key, i);
  }
  expectSameOrderAsAStableSort(signed_items, true);
  expectSameOrderAsAStableSort(unsigned_items, true);
  expectSameOrderAsAStableSort(std::vector<std::pair<std::uint64_t, int>>{{7, 0}, {7, 1}, {7, 2}},
                               true);
}

TEST(RadixSort, LeavesEmptyAndSingleInputsAlone) {
  std::vector<std::pair<std::uint64_t, int>> none;
  radixSortByKey(none);
  EXPECT_TRUE(none.empty());
  std::vector<std::pair<std::uint64_t, int>> one{{42, 7}};
  radixSortByKey(one);
  EXPECT_EQ(one.front(), std::make_pair(std::uint64_t{42}, 7));
}

}  // namespace
}  // namespace taiga
