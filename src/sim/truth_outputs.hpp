#pragma once
// Truth files of a simulated recording besides the bag: trees.csv, georef_truth.yaml and the
// effective scenario.yaml (docs/simulator.md, "Outputs").

#include <filesystem>
#include <string>

#include "taiga/sim/simulator.hpp"

namespace taiga::sim::detail {

const char* speciesName(Species species);

/// Writes `text` to `path`; std::runtime_error naming the file when it cannot.
void writeText(const std::filesystem::path& path, const std::string& text);

/// One row per stem: id, base position in the world frame, DBH, height, lean, species.
void writeTreesCsv(const std::filesystem::path& path, const Scene& scene);
/// The world frame in the projected CRS of scenario.gnss.georef_epsg.
void writeGeorefTruthYaml(const std::filesystem::path& path, const Simulation& simulation);
/// The effective scenario (after the overrides and the command line), with the duration used.
void writeScenarioYaml(const std::filesystem::path& path, const Simulation& simulation);

}  // namespace taiga::sim::detail
