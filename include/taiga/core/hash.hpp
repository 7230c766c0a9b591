#pragma once
// A hash for 64-bit keys whose bits are structured (packed voxel coordinates): std::hash is the
// identity for integers, which puts neighbouring voxels into neighbouring slots of an
// open-addressing table and makes long probe runs. This mixes all bits into the low ones
// (the xor-shift-multiply finalizer of splitmix64).

#include <cstddef>
#include <cstdint>

namespace taiga {

struct MixedKeyHash {
  std::size_t operator()(std::uint64_t key) const {
    key ^= key >> 31;
    key *= 0x9e3779b97f4a7c15ULL;
    key ^= key >> 29;
    return static_cast<std::size_t>(key);
  }
};

}  // namespace taiga
