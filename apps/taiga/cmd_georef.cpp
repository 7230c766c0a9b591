// taiga georef: put a finished trajectory into a national coordinate system by fitting it to
// GNSS fixes (docs/georeferencing.md). The work is taiga::georef::georeference; this file reads
// the inputs and prints the result.
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <optional>

#include "command.hpp"
#include "georef_als.hpp"
#include "recording_options.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/georef/georeference.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::app {
namespace {
/// Settings not given on the command line come from the config's georef section.
struct GeorefOptions {
  std::string trajectory, gnss, out, config;
  std::string method;  ///< empty: not given
  std::optional<int> epsg;
  std::optional<double> max_horizontal_sigma_m, max_gap_s;
  AlsGeorefOptions als;
};

int runGeoref(const GeorefOptions& options) {
  if (!options.als.als.empty()) {
    if (options.als.run.empty())
      throw InputError("taiga georef --als: give the run: --run RUN_DIR");
    AlsGeorefOptions als = options.als;
    als.out = options.out;
    als.epsg = options.epsg;
    return runAlsGeoref(als);
  }
  if (options.trajectory.empty() || options.gnss.empty())
    throw InputError("taiga georef: give --traj and --gnss (GNSS fixes), or --als and --run");
  const SystemConfig config = loadConfig(options.config);
  const Trajectory trajectory = io::readTrajectory(options.trajectory);
  const georef::GnssInput input = georef::readGnssInput(options.gnss, config);
  georef::GeorefSettings settings = georef::settingsFrom(config.georef);
  if (!options.method.empty()) settings.method = georef::parseMethod(options.method);
  if (options.epsg) settings.epsg = *options.epsg;
  if (options.max_horizontal_sigma_m)
    settings.gating.max_horizontal_sigma_m = *options.max_horizontal_sigma_m;
  if (options.max_gap_s) settings.association.max_gap_s = *options.max_gap_s;
  const georef::Georeference georeference = georef::georeference(
      trajectory, input, settings, config.rig, options.trajectory, options.gnss);
  const std::string name = std::filesystem::path(options.trajectory).stem().string();
  georef::writeGeoreference(options.out, georeference, name);

  const georef::GeorefReport& report = georeference.report;
  const georef::GeorefFit& result = report.fit;
  fmt::print("georef {}: {} of {} fixes used ({} gated, {} outside the trajectory, {} outliers), "
             "residual RMS {:.2f} m horizontal, {:.2f} m vertical\n",
             report.method, result.inliers, report.fixes_total,
             report.gated_no_fix + report.gated_sigma + report.gated_invalid,
             report.outside_span + report.in_gap, result.outliers, result.horizontal_rms_m,
             result.vertical_rms_m);
  fmt::print(
      "1-sigma: east {:.3f} m, north {:.3f} m, up {:.3f} m, roll {:.3f} deg, pitch {:.3f} "
      "deg, yaw {:.3f} deg\n",
      result.sigma[0], result.sigma[1], result.sigma[2], result.sigma[3] * kDegPerRad,
      result.sigma[4] * kDegPerRad, result.sigma[5] * kDegPerRad);
  if (result.error_model) {
    const georef::GnssErrorModel& model = *result.error_model;
    fmt::print(
        "error model: Gauss-Markov, correlation time {:g} s (configured {:g}), white share {:g}, "
        "{:.0f} % of the reported sigmas' swings believed; observed errors {:.2f}x the reported "
        "sigmas horizontally, {:.2f}x vertically; worth {:.1f} independent fixes\n",
        model.correlation_time_s, model.configured_correlation_time_s, model.white_share,
        100.0 * model.sigma_trust, model.sigma_scale_horizontal, model.sigma_scale_up,
        model.independent_fixes);
    // Whitened residuals still correlated: the errors drift for longer than even 3x tau.
    constexpr double kMaxLagOneCorrelation = 0.3;
    if (model.whitened_lag_one_correlation > kMaxLagOneCorrelation)
      fmt::print(stderr,
                 "taiga georef: warning: the GNSS errors stay correlated for longer than the "
                 "error model allows (whitened lag-one correlation {:.2f}): the 1-sigma may be too "
                 "small; raise georef.error_correlation_time_s (now {:g} s)\n",
                 model.whitened_lag_one_correlation, model.configured_correlation_time_s);
  }
  fmt::print("wrote {}\n", options.out);
  if (!result.converged) {
    fmt::print(stderr, "taiga georef: warning: {} did not converge in {} iterations\n",
               report.method, result.iterations);
  }
  return kExitOk;
}
}  // namespace

Command addGeorefCommand(CLI::App& tool) {
  auto options = std::make_shared<GeorefOptions>();
  CLI::App* parser = tool.add_subcommand(
      "georef", "Fit a trajectory to GNSS fixes and write it in a projected coordinate system");
  parser->add_option("--traj", options->trajectory,
                     "Trajectory to georeference (TUM or KITTI), T_world_body");
  parser->add_option("--gnss", options->gnss,
                     "Recording, or CSV file of fixes (docs/georeferencing.md)");
  parser->add_option("--als", options->als.als,
                     "Instead of GNSS: airborne lidar tiles (LAS in the grid, or directories of "
                     "them) to register the map of --run to (docs/georeferencing.md, ALS)");
  parser->add_option("--run", options->als.run, "With --als: the run directory of `taiga run`");
  parser->add_option("--guess", options->als.guess,
                     "With --als: the map origin's E,N and heading (deg from grid east), when the "
                     "run has no GNSS georeference (default: RUN/georef/georef.yaml)");
  parser
      ->add_option("--search-m", options->als.search_m,
                   "With --als: half width of the position search, m (default 8 from GNSS, 25 "
                   "from --guess)")
      ->check(CLI::PositiveNumber);
  parser
      ->add_option("--search-deg", options->als.search_deg,
                   "With --als: half width of the heading search, deg (default 8 / 25)")
      ->check(CLI::Range(0.5, 180.0));
  parser->add_option("--method", options->method,
                     "Fitting method (default: georef.method of --config, robust)")
      ->check(CLI::IsMember({"closed", "pf3", "pf6", "robust"}));
  parser->add_option("--out", options->out, "Output directory")->required();
  parser->add_option("--epsg", options->epsg,
                     "Projected CRS of the outputs (default: georef.epsg, 3067: ETRS-TM35FIN)");
  parser->add_option("--max-horizontal-sigma", options->max_horizontal_sigma_m,
                     "Drop fixes whose reported horizontal 1-sigma exceeds this, m (default: "
                     "georef.max_horizontal_sigma_m, 5)")
      ->check(CLI::PositiveNumber);
  parser->add_option("--max-gap", options->max_gap_s,
                     "Drop fixes between trajectory poses further apart than this, s (default: "
                     "georef.max_gap_s, 1)")
      ->check(CLI::PositiveNumber);
  addConfigOption(*parser, options->config);
  return {parser, [options] { return runGeoref(*options); }, options};
}

}  // namespace taiga::app
