// taiga simulate: a synthetic forest recording with exact ground truth.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct SimulateOptions {
  std::string scenario = "mixed";
  double duration_s = 60.0;
  unsigned seed = 1;
  std::string out;
};
}  // namespace

Command addSimulateCommand(CLI::App& tool) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* parser = tool.add_subcommand(
      "simulate", "Simulate a lidar-inertial recording in a generated forest, with ground truth");
  parser->add_option("--scenario", options->scenario, "Forest and motion scenario")
      ->capture_default_str();
  parser->add_option("--duration", options->duration_s, "Recording length, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--seed", options->seed, "Random seed; the same seed gives the same recording")
      ->capture_default_str();
  parser->add_option("--out", options->out, "Output directory")->required();
  return {parser, notImplemented("simulate", "the forest and sensor simulator is issue 4"),
          options};
}

}  // namespace taiga::app
