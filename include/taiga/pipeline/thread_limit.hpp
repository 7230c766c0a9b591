#pragma once
// A cap on the worker threads of TBB's parallel stages, for as long as it lives
// (compute.threads, `taiga run --threads`, `taiga trees --threads`). The pipeline's own threads
// (reading, building the next local map, the mapping back end) are not capped;
// docs/architecture.md lists them and what they cost.

#include <tbb/global_control.h>

#include <cstddef>
#include <optional>

namespace taiga::pipeline {

class ThreadLimit {
 public:
  /// `threads` 0 (or less): no cap, one thread per core.
  explicit ThreadLimit(int threads) {
    if (threads > 0)
      control_.emplace(tbb::global_control::max_allowed_parallelism,
                       static_cast<std::size_t>(threads));
  }

 private:
  std::optional<tbb::global_control> control_;
};

}  // namespace taiga::pipeline
