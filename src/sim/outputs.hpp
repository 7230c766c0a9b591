#pragma once
// The side files of a simulated recording: rig.yaml and scene.json.

#include <filesystem>

#include "taiga/sim/simulator.hpp"

namespace taiga::sim::detail {

/// The configuration `taiga run` needs for the recording (keys of taiga::SystemConfig only),
/// with the simulated sensor noise as comments.
void writeRigYaml(const std::filesystem::path& path, const Simulation& simulation);

/// Scenario, seed, georeference, sensor settings, statistics and the truth of every object.
void writeSceneJson(const std::filesystem::path& path, const Simulation& simulation,
                    const SimulationSummary& summary);

}  // namespace taiga::sim::detail
