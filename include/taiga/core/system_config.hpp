#pragma once
// The whole configuration of a taiga run: one section per module. Sections are added here as the
// modules that own them land.

#include "taiga/core/config.hpp"
#include "taiga/core/rig_config.hpp"

namespace taiga {

struct SystemConfig final : ConfigSection {
  RigConfig rig;

  void visit(ConfigVisitor& v) override {
    v.section("rig", rig, "sensor rig: extrinsics, clock offset and units");
  }
};

}  // namespace taiga
