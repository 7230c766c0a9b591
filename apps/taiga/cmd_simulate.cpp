// taiga simulate: a synthetic forest recording with exact ground truth (docs/simulator.md).
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>

#include "command.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/sim/als.hpp"
#include "taiga/sim/realism.hpp"
#include "taiga/sim/reference_cloud.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::app {
namespace {
struct SimulateOptions {
  std::string scenario = "mixed";
  std::string realism = "ideal";       // preset of the errors the rig.yaml does not state
  std::string overrides;               // YAML file overriding scenario fields
  std::optional<double> duration_s;    // default: the scenario's duration_s
  std::uint64_t seed = 1;
  std::string out;
  std::optional<int> beams;            // command-line values win over the scenario and the file
  std::optional<int> columns;
  std::optional<int> sub_rays;
  std::optional<std::string> pcap_profile;  // also capture.pcap + capture.json
  bool reference_cloud = false;        // also write reference_cloud.las (a TLS survey)
  sim::ReferenceCloudParams reference;
  std::optional<double> als_pulses_per_m2;  // also write als.las (an airborne survey)
};

int runSimulate(const SimulateOptions& options) {
  // Precedence: the named scenario, the realism preset, the overrides file, the command line.
  sim::Scenario scenario = sim::scenarioByName(options.scenario);
  sim::applyRealism(options.realism, scenario);
  if (!options.overrides.empty()) sim::applyScenarioOverrides(options.overrides, scenario);
  if (options.beams) scenario.lidar.beams = *options.beams;
  if (options.columns) scenario.lidar.columns = *options.columns;
  if (options.sub_rays) scenario.lidar.sub_rays = *options.sub_rays;
  if (options.pcap_profile) scenario.output.pcap_profile = *options.pcap_profile;
  const double duration_s = options.duration_s.value_or(scenario.duration_s);
  const auto start = std::chrono::steady_clock::now();
  const sim::Simulation simulation(scenario, duration_s, options.seed);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const sim::SceneStats stats = simulation.scene().stats();
  fmt::print(
      "scene '{}' (seed {}): {:.2f} ha, {} trees, {} triangles, {} curve segments, built in {:.1f} "
      "s\n",
      scenario.name, options.seed, stats.area_ha, simulation.scene().trees().size(),
      stats.triangles, stats.curve_segments, build_s);
  if (simulation.scanCount() == 0) {
    throw InputError(fmt::format("--duration {}: shorter than one lidar sweep ({} s)", duration_s,
                                 simulation.lidar().scanPeriod_s()));
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
      summary.imu_samples, summary.gnss_fixes, summary.path_length_m, duration_s,
      summary.simulate_s, duration_s / summary.simulate_s);
  if (options.reference_cloud) {
    const auto start_reference = std::chrono::steady_clock::now();
    const std::filesystem::path path = std::filesystem::path(options.out) / "reference_cloud.las";
    const sim::ReferenceCloudSummary reference =
        sim::writeReferenceCloud(simulation, path, options.reference);
    fmt::print(
        "wrote {}: {} points from {} stations ({} rays, {:.0f} MB) in {:.1f} s\n", path.string(),
        reference.points, reference.stations, reference.rays,
        static_cast<double>(reference.file_bytes) / 1e6,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_reference).count());
  }
  if (options.als_pulses_per_m2) {
    const auto start_als = std::chrono::steady_clock::now();
    const std::filesystem::path path = std::filesystem::path(options.out) / "als.las";
    const sim::AlsSummary als =
        sim::writeAls(simulation, path, {.pulses_per_m2 = *options.als_pulses_per_m2});
    fmt::print(
        "wrote {}: {} points of {} pulses over {:.2f} ha ({} last returns, {} ground; {:.0f} MB) "
        "in EPSG:{} in {:.1f} s\n",
        path.string(), als.points, als.pulses, als.area_m2 / 1e4, als.last_returns,
        als.ground_points, static_cast<double>(als.file_bytes) / 1e6, scenario.gnss.georef_epsg,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_als).count());
  }
  return kExitOk;
}
}  // namespace

Command addSimulateCommand(CLI::App& tool) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* parser = tool.add_subcommand(
      "simulate", "Simulate a lidar-inertial recording in a generated forest, with ground truth");
  std::string names;
  for (const std::string& name : sim::scenarioNames()) names += (names.empty() ? "" : ", ") + name;
  parser
      ->add_option("--scenario", options->scenario,
                   "Forest, rig and motion scenario: " + names +
                       " (hyphens and underscores are interchangeable)")
      ->capture_default_str();
  parser
      ->add_option("--realism", options->realism,
                   "Errors of the rig that its rig.yaml does not state (IMU noise and biases, "
                   "extrinsics, time offset, lidar noise, lost packets, wind): ideal, typical, "
                   "harsh; the truth goes to rig_truth.yaml (docs/simulator.md, \"Realism\")")
      ->capture_default_str()
      ->check(CLI::IsMember(sim::realismNames()));
  parser->add_option("--overrides", options->overrides,
                     "YAML file overriding scenario fields (forest:, motion:, lidar:, imu:, gnss:; "
                     "see docs/simulator.md); a recording's scenario.yaml reproduces it");
  parser->add_option("--duration", options->duration_s,
                     "Recording length, s (default: the scenario's, e.g. 60 for mixed, 180 for "
                     "handheld-loop)")
      ->check(CLI::PositiveNumber);
  parser->add_option("--seed", options->seed, "Random seed; the same seed gives the same recording")
      ->capture_default_str();
  parser->add_option("--out", options->out, "Output directory")->required();
  parser
      ->add_option("--beams", options->beams,
                   "Lidar rows (128, 64, 32, ...), subsampled from the metadata (default 128)")
      ->check(CLI::Range(1, 128));
  parser
      ->add_option("--columns", options->columns,
                   "Lidar columns per rotation (512, 1024, 2048; default 1024)")
      ->check(CLI::IsMember({512, 1024, 2048}));
  parser
      ->add_option("--sub-rays", options->sub_rays,
                   "Rays per beam at depth edges for the beam divergence (1: none, about 2x "
                   "faster; default 4)")
      ->check(CLI::Range(1, 8));
  parser
      ->add_option("--pcap", options->pcap_profile,
                   "Also write capture.pcap + capture.json: the scans and IMU samples as an Ouster "
                   "sensor's UDP packets with its metadata, in this lidar profile")
      ->expected(0, 1)
      ->default_str("RNG19_RFL8_SIG16_NIR16")
      ->check(CLI::IsMember({"LEGACY", "RNG19_RFL8_SIG16_NIR16", "RNG15_RFL8_NIR8"}));
  parser->add_flag("--reference-cloud", options->reference_cloud,
                   "Also write reference_cloud.las: a dense, noise-free cloud of the plot as a "
                   "terrestrial scanner records it from stations along the true path");
  parser
      ->add_option("--reference-spacing", options->reference.station_spacing_m,
                   "Path length between reference stations, m")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  parser
      ->add_option("--reference-step", options->reference.angular_step_deg,
                   "Angular step of the reference scanner, deg (0.06: 1 cm at 10 m)")
      ->capture_default_str()
      ->check(CLI::Range(0.005, 5.0));
  parser
      ->add_option("--reference-voxel", options->reference.voxel_m,
                   "Voxel size thinning the reference cloud, m (0: keep every return)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  parser
      ->add_option(
          "--als", options->als_pulses_per_m2,
          "Also write als.las: the plot as an airborne laser scanner records it (this many "
          "pulses per m^2, first and last returns, ground classified) in the projected "
          "CRS of georef_truth.yaml")
      ->expected(0, 1)
      ->default_str("5")
      ->check(CLI::Range(0.1, 1000.0));
  return {parser, [options] { return runSimulate(*options); }, options};
}

}  // namespace taiga::app
