#pragma once
// A short simulated recording written to a directory and read back as `taiga run` would read it.
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {

struct Written {
  SystemConfig rig;
  std::vector<io::Scan> scans;
  std::size_t imu_samples = 0;
  std::vector<double> imu_stamps_s;
};

/// The `mixed` scenario with `overrides` (scenario YAML), seed 6.
inline Written simulateAndRead(const std::string& overrides, const test::TempDir& dir,
                               double duration_s, Scenario* scenario_out = nullptr) {
  Scenario s = scenarioByName("mixed");
  applyScenarioOverridesText(overrides, "test.yaml", s);
  writeSimulation(Simulation(s, duration_s, 6), dir.path());
  if (scenario_out) *scenario_out = s;
  Written w;
  io::readConfigYaml(dir.file("rig.yaml"), w.rig);
  io::Recording recording =
      io::openRecording(dir.file("recording.bag"), w.rig.recording, w.rig.rig);
  while (auto event = recording.next()) {
    if (auto* scan = std::get_if<io::Scan>(&*event)) w.scans.push_back(std::move(*scan));
    if (const auto* imu = std::get_if<ImuSample>(&*event)) {
      ++w.imu_samples;
      w.imu_stamps_s.push_back(imu->t_s);
    }
  }
  return w;
}

}  // namespace taiga::sim
