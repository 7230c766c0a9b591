#pragma once
// The side files of a simulated recording: rig.yaml and scene.json.

#include <filesystem>

#include "taiga/sim/simulator.hpp"

namespace taiga::sim::detail {

/// Which rig a configuration describes: the one a user would write (nominal extrinsics from the
/// drawing, datasheet noise, no time offset) or the one the simulator built.
enum class RigView { kStated, kTrue };

/// The configuration `taiga run` needs for the recording (keys of taiga::SystemConfig only):
/// rig.yaml (kStated) or rig_truth.yaml (kTrue), with the errors of the true rig that no
/// configuration key can hold as comments.
void writeRigYaml(const std::filesystem::path& path, const Simulation& simulation, RigView view);

/// Scenario, seed, georeference, sensor settings, statistics and the truth of every object.
void writeSceneJson(const std::filesystem::path& path, const Simulation& simulation,
                    const SimulationSummary& summary);

}  // namespace taiga::sim::detail
