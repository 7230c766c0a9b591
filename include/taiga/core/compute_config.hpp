#pragma once
// How much of the machine a run may use (docs/configuration.md, compute).

#include "taiga/core/config.hpp"

namespace taiga {

struct ComputeConfig final : ConfigSection {
  /// Worker threads of the parallel stages (registration, voxel statistics, loop-closure
  /// search); 0: one per core. A harvester's computer also runs the crane, the display and the
  /// planner: 1 leaves them the other cores (docs/architecture.md, "Threads").
  int threads = 0;

  void visit(ConfigVisitor& v) override {
    v.field("threads", threads,
            "worker threads of the parallel stages; 0: one per core (taiga run --threads)");
  }
  void validate() const override { requireInRange("threads", threads, 0, 1024, ""); }
};

}  // namespace taiga
