#pragma once
// Deterministic parallel reduction: body(i, partial) runs over [0, n) in fixed blocks of
// kBlockSize items (blocks in parallel with TBB, items in order within a block), and the block
// partials are combined in block order, so the floating-point result is the same for any number
// of threads.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace taiga::registration::detail {

inline constexpr std::size_t kBlockSize = 256;

template <class Partial, class Body, class Combine>
Partial reduceInBlocks(std::size_t n, const Body& body, const Combine& combine) {
  const std::size_t num_blocks = (n + kBlockSize - 1) / kBlockSize;
  std::vector<Partial> partials(num_blocks);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_blocks),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t b = range.begin(); b != range.end(); ++b) {
                        const std::size_t end = std::min(n, (b + 1) * kBlockSize);
                        for (std::size_t i = b * kBlockSize; i < end; ++i) body(i, partials[b]);
                      }
                    });
  Partial total{};
  for (const Partial& p : partials) combine(total, p);
  return total;
}

}  // namespace taiga::registration::detail
