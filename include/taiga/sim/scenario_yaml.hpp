#pragma once
// Scenarios as YAML: `taiga simulate --overrides FILE.yaml` changes any field of the scenario, and
// every simulation writes its effective scenario as scenario.yaml, which reproduces the run:
//
//   name: handheld-loop        # the scenario the file describes (informative; one of the names)
//   duration_s: 180            # used when --duration is not given
//   forest: {stems_per_ha: 1200, species: {pine: 0.2, spruce: 0.7, birch: 0.1}}
//   motion: {speed_mps: 1.1}
//   lidar: {beams: 64}
//   imu: {orientation_output: true}
//   gnss: {noise: false}
//
// The keys are the field names of include/taiga/sim/scenario.hpp, listed once in the tables of
// src/sim/scenario_yaml.cpp (one line per field, with its documentation and valid range). Keys
// the file does not mention keep their value. Unknown keys, wrong types and values out of range
// are InputErrors naming the file, line and key path, e.g.
//   "overrides.yaml:3:3: motion.sped_mps: unknown key; did you mean 'speed_mps'? ...".

#include <filesystem>
#include <string>
#include <string_view>

#include "taiga/sim/scenario.hpp"

namespace taiga::sim {

/// Overrides the fields of `scenario` that the file sets, then checks the whole scenario.
void applyScenarioOverrides(const std::filesystem::path& path, Scenario& scenario);
/// The same from YAML text; `source_name` stands for the file name in messages.
void applyScenarioOverridesText(std::string_view text, std::string_view source_name,
                                Scenario& scenario);
/// Every field of `scenario` as YAML, with each field's documentation as a comment; reading it
/// back into any scenario gives `scenario` exactly (numbers are written with full precision).
std::string scenarioYaml(const Scenario& scenario);

}  // namespace taiga::sim
