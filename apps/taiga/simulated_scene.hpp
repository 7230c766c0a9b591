#pragma once
// The simulated scene of a recording that `taiga simulate` wrote, generated again from its
// scenario.yaml (every field, duration included) and the seed in its scene.json: the same
// scenario, duration and seed give the same scene (docs/simulator.md).

#include <filesystem>

#include "taiga/sim/simulator.hpp"

namespace taiga::app {

/// InputError naming the file when scenario.yaml or scene.json is missing or malformed.
sim::Simulation simulationOfRecording(const std::filesystem::path& recording_dir);

}  // namespace taiga::app
