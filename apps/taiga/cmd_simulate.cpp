// taiga simulate: a synthetic forest recording with exact ground truth (docs/simulator.md).
#include <fmt/format.h>

#include <chrono>
#include <memory>

#include "command.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::app {
namespace {
struct SimulateOptions {
  std::string scenario = "mixed";
  double duration_s = 60.0;
  std::uint64_t seed = 1;
  std::string out;
  int beams = 128;
  int columns = 1024;
  int sub_rays = 4;
};

int runSimulate(const SimulateOptions& options) {
  sim::Scenario scenario = sim::scenarioByName(options.scenario);
  scenario.lidar.beams = options.beams;
  scenario.lidar.columns = options.columns;
  scenario.lidar.sub_rays = options.sub_rays;
  const auto start = std::chrono::steady_clock::now();
  const sim::Simulation simulation(scenario, options.duration_s, options.seed);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const sim::SceneStats stats = simulation.scene().stats();
  fmt::print(
      "scene '{}' (seed {}): {:.2f} ha, {} trees, {} triangles, {} curve segments, built in {:.1f} "
      "s\n",
      scenario.name, options.seed, stats.area_ha, simulation.scene().trees().size(),
      stats.triangles, stats.curve_segments, build_s);
  if (simulation.scanCount() == 0) {
    throw InputError(fmt::format("--duration {}: shorter than one lidar sweep ({} s)",
                                 options.duration_s, simulation.lidar().scanPeriod_s()));
  }
  Progress progress("simulating", simulation.scanCount(), "scans");
  const sim::SimulationSummary summary = sim::writeSimulation(
      simulation, options.out, [&](std::size_t done, std::size_t) { progress.update(done); });
  progress.finish();
  fmt::print(
      "wrote {}: {} scans ({} .. {} points, {:.0f} on average), {} IMU samples, {} GNSS fixes, "
      "path {:.1f} m; "
      "simulated {:.1f} s of data in {:.1f} s ({:.2f}x real time)\n",
      options.out, summary.scans, summary.min_points_per_scan, summary.max_points_per_scan,
      summary.scans ? static_cast<double>(summary.points) / summary.scans : 0.0,
      summary.imu_samples, summary.gnss_fixes, summary.path_length_m, options.duration_s,
      summary.simulate_s, options.duration_s / summary.simulate_s);
  return kExitOk;
}
}  // namespace

Command addSimulateCommand(CLI::App& tool) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* parser = tool.add_subcommand(
      "simulate", "Simulate a lidar-inertial recording in a generated forest, with ground truth");
  parser
      ->add_option(
          "--scenario", options->scenario,
          "Forest and motion scenario: mixed, sparse_pine, dense_spruce, open_field, strip_road")
      ->capture_default_str();
  parser->add_option("--duration", options->duration_s, "Recording length, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--seed", options->seed, "Random seed; the same seed gives the same recording")
      ->capture_default_str();
  parser->add_option("--out", options->out, "Output directory")->required();
  parser
      ->add_option("--beams", options->beams,
                   "Lidar rows (128, 64, 32, ...), subsampled from the metadata")
      ->check(CLI::Range(1, 128))
      ->capture_default_str();
  parser->add_option("--columns", options->columns, "Lidar columns per rotation (512, 1024, 2048)")
      ->check(CLI::IsMember({512, 1024, 2048}))
      ->capture_default_str();
  parser
      ->add_option(
          "--sub-rays", options->sub_rays,
          "Rays per beam at depth edges for the beam divergence (1: none, about 2x faster)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  return {parser, [options] { return runSimulate(*options); }, options};
}

}  // namespace taiga::app
