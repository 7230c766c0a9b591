#pragma once
// The live tests' recording: a 4 s simulated walk with its Ouster capture in the low-data-rate
// profile (32 beams x 512 columns), written by `taiga simulate --pcap` into DIR/sim.

#include <gtest/gtest.h>

#include <filesystem>

#include "run_taiga.hpp"
#include "temp_dir.hpp"

namespace taiga::test {

inline std::filesystem::path simulateCapture(const TempDir& dir) {
  const auto sim = dir.file("sim");
  const TaigaResult r = runTaiga(
      "simulate --scenario mixed --duration 4 --beams 32 --columns 512 --seed 4 --pcap "
      "RNG15_RFL8_NIR8 --out " +
      sim.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return sim;
}

}  // namespace taiga::test
