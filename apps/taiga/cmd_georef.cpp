// taiga georef: put a finished trajectory into a national coordinate system by fitting it to
// GNSS fixes (docs/georeferencing.md). The fitting is taiga::georef; this file reads the inputs,
// turns empty or non-overlapping inputs into errors naming the file, and writes the outputs.
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/georef/georef_files.hpp"
#include "taiga/georef/orientation.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::app {
namespace {
struct GeorefOptions {
  std::string trajectory, gnss, out, config;
  std::string method = "robust";
  int epsg = 3067;
  double max_horizontal_sigma_m = georef::FixGating{}.max_horizontal_sigma_m;
  double max_gap_s = georef::AssociationOptions{}.max_gap_s;
};

/// The fit's input: the fixes associated with the trajectory, or an InputError that says why
/// there are none.
georef::Association associate(const GeorefOptions& options, const Trajectory& trajectory,
                              const georef::GnssInput& input,
                              const georef::PreparedFixes& prepared) {
  if (input.fixes.empty())
    throw InputError(fmt::format("{}: no GNSS fixes{}", options.gnss,
                                 input.from_recording
                                     ? " (recording.gnss_topic in --config names the topic)"
                                     : " after the header"));
  if (prepared.fixes.empty())
    throw InputError(fmt::format(
        "{}: all {} GNSS fixes were gated: {} without a fix (status -1), {} with a reported "
        "horizontal sigma above --max-horizontal-sigma {} m, {} with invalid values",
        options.gnss, prepared.total, prepared.gated_no_fix, prepared.gated_sigma,
        options.max_horizontal_sigma_m, prepared.gated_invalid));
  georef::AssociationOptions association_options;
  association_options.max_gap_s = options.max_gap_s;
  georef::Association association =
      georef::associateFixes(trajectory, prepared.fixes, association_options);
  if (association.pairs.size() < 3)
    throw InputError(fmt::format(
        "{} (t {:.3f} to {:.3f} s) and the fixes of {} (t {:.3f} to {:.3f} s) overlap at only {} "
        "fix(es), at least 3 are needed ({} outside the trajectory's time span, {} in gaps "
        "longer than --max-gap {} s); are both on the same clock?",
        options.trajectory, trajectory.startTime(), trajectory.endTime(), options.gnss,
        prepared.fixes.front().t_s, prepared.fixes.back().t_s, association.pairs.size(),
        association.outside_span, association.in_gap, options.max_gap_s));
  return association;
}

georef::GeorefFit fit(const GeorefOptions& options, const SystemConfig& config,
                      const georef::GnssInput& input, const georef::Association& association) {
  const georef::GeorefMethod method = georef::parseMethod(options.method);
  const georef::FitOptions fit_options;
  switch (method) {
    case georef::GeorefMethod::kClosed:
      return georef::fitClosed(association.pairs, fit_options);
    case georef::GeorefMethod::kPf3:
      return georef::fitPf3(association.pairs, fit_options);
    case georef::GeorefMethod::kPf6: {
      if (!input.from_recording)
        throw InputError(fmt::format(
            "{}: --method pf6 needs the IMU's absolute orientation, which a fixes CSV does not "
            "carry; give the recording, or use --method robust or pf3",
            options.gnss));
      std::vector<double> times;
      for (const georef::AssociatedFix& pair : association.pairs) times.push_back(pair.fix.t_s);
      const auto orientations = georef::orientationsAt(
          georef::absoluteOrientations(input.imu_with_orientation, config.rig.T_body_imu), times);
      try {
        return georef::fitPf6(association.pairs, orientations, fit_options);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}", options.gnss, e.what()));
      }
    }
    case georef::GeorefMethod::kRobust:
      return georef::fitRobust(association.pairs, fit_options);
  }
  throw InputError("unknown georef method");  // unreachable: CLI11 checks the name
}

int runGeoref(const GeorefOptions& options) {
  const geo::CoordinateConverter converter(options.epsg);  // InputError for unknown codes
  const SystemConfig config = loadConfig(options.config);
  const Trajectory trajectory = io::readTrajectory(options.trajectory);
  if (trajectory.empty())
    throw InputError(fmt::format("{}: the trajectory has no poses", options.trajectory));

  const georef::GnssInput input = georef::readGnssInput(options.gnss, config);
  georef::FixGating gating;
  gating.max_horizontal_sigma_m = options.max_horizontal_sigma_m;
  const georef::PreparedFixes prepared = georef::prepareFixes(input.fixes, gating, converter);
  const georef::Association association = associate(options, trajectory, input, prepared);
  const georef::GeorefFit result = fit(options, config, input, association);

  georef::GeorefReport report;
  report.method = options.method;
  report.epsg = converter.epsg();
  report.crs_name = converter.crsName();
  report.trajectory_file = options.trajectory;
  report.gnss_file = options.gnss;
  report.origin = prepared.origin;
  report.origin_grid = converter.toProjected(prepared.origin);
  report.fit = result;
  report.T_epsg_world = georef::tangentPlaneEpsgWorld(result.T_enu_world, prepared.origin, converter);
  report.fixes_total = prepared.total;
  report.gated_no_fix = prepared.gated_no_fix;
  report.gated_sigma = prepared.gated_sigma;
  report.gated_invalid = prepared.gated_invalid;
  report.outside_span = association.outside_span;
  report.in_gap = association.in_gap;
  report.associated = association.pairs.size();

  const std::filesystem::path out(options.out);
  std::filesystem::create_directories(out);
  const std::vector<georef::GridPose> grid =
      georef::trajectoryInGrid(trajectory, result.T_enu_world, prepared.origin, converter);
  georef::writeGridCsv(out / fmt::format("trajectory_epsg{}.csv", converter.epsg()), grid);
  georef::writeGeoJson(out / "trajectory.geojson", grid, converter.epsg(),
                       std::filesystem::path(options.trajectory).stem().string());
  georef::writeGeorefYaml(out / "georef.yaml", report);

  constexpr double kDeg = 57.29577951308232;
  fmt::print("georef {}: {} of {} fixes used ({} gated, {} outside the trajectory, {} outliers), "
             "residual RMS {:.2f} m horizontal, {:.2f} m vertical\n",
             options.method, result.inliers, prepared.total, prepared.gated(),
             association.outside_span + association.in_gap, result.outliers,
             result.horizontal_rms_m, result.vertical_rms_m);
  fmt::print("1-sigma: east {:.3f} m, north {:.3f} m, up {:.3f} m, roll {:.3f} deg, pitch {:.3f} "
             "deg, yaw {:.3f} deg\n",
             result.sigma[0], result.sigma[1], result.sigma[2], result.sigma[3] * kDeg,
             result.sigma[4] * kDeg, result.sigma[5] * kDeg);
  fmt::print("wrote {}\n", out.string());
  if (!result.converged) {
    fmt::print(stderr, "taiga georef: warning: {} did not converge in {} iterations\n",
               options.method, result.iterations);
  }
  return kExitOk;
}
}  // namespace

Command addGeorefCommand(CLI::App& tool) {
  auto options = std::make_shared<GeorefOptions>();
  CLI::App* parser = tool.add_subcommand(
      "georef", "Fit a trajectory to GNSS fixes and write it in a projected coordinate system");
  parser->add_option("--traj", options->trajectory, "Trajectory to georeference (TUM or KITTI), T_world_body")
      ->required();
  parser->add_option("--gnss", options->gnss, "Recording, or CSV file of fixes (docs/georeferencing.md)")
      ->required();
  parser->add_option("--method", options->method, "Fitting method (robust is recommended)")
      ->check(CLI::IsMember({"closed", "pf3", "pf6", "robust"}))
      ->capture_default_str();
  parser->add_option("--out", options->out, "Output directory")->required();
  parser->add_option("--epsg", options->epsg, "Projected CRS of the outputs (3067: ETRS-TM35FIN)")
      ->capture_default_str();
  parser->add_option("--max-horizontal-sigma", options->max_horizontal_sigma_m,
                     "Drop fixes whose reported horizontal 1-sigma exceeds this, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--max-gap", options->max_gap_s,
                     "Drop fixes between trajectory poses further apart than this, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  addConfigOption(*parser, options->config);
  return {parser, [options] { return runGeoref(*options); }, options};
}

}  // namespace taiga::app
