#include "simulated_scene.hpp"

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "taiga/core/errors.hpp"
#include "taiga/sim/scenario_yaml.hpp"

namespace taiga::app {

sim::Simulation simulationOfRecording(const std::filesystem::path& recording_dir) {
  const std::filesystem::path scenario_path = recording_dir / "scenario.yaml";
  const std::filesystem::path scene_path = recording_dir / "scene.json";
  for (const auto& path : {scenario_path, scene_path}) {
    if (!std::filesystem::exists(path))
      throw InputError(fmt::format("{}: missing: --scene expects a directory written by taiga "
                                   "simulate",
                                   path.string()));
  }
  sim::Scenario scenario;
  sim::applyScenarioOverrides(scenario_path, scenario);  // every field, the duration included
  std::ifstream in(scene_path);
  const nlohmann::json scene = nlohmann::json::parse(in, nullptr, false);
  if (scene.is_discarded() || !scene.contains("seed") || !scene["seed"].is_number_unsigned())
    throw InputError(fmt::format("{}: seed: expected a JSON object with an unsigned integer seed",
                                 scene_path.string()));
  return sim::Simulation(scenario, scenario.duration_s, scene["seed"].get<std::uint64_t>());
}

}  // namespace taiga::app
