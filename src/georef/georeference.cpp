#include "taiga/georef/georeference.hpp"

#include <fmt/format.h>

#include "taiga/core/errors.hpp"
#include "taiga/georef/orientation.hpp"

namespace taiga::georef {
namespace {

PreparedFixes prepare(const GnssInput& input, const GeorefSettings& settings,
                      const geo::CoordinateConverter& converter, const std::string& gnss_name) {
  if (input.fixes.empty())
    throw InputError(fmt::format("{}: no GNSS fixes{}", gnss_name,
                                 input.from_recording
                                     ? " (recording.gnss_topic in the config names the topic)"
                                     : " after the header"));
  PreparedFixes prepared = prepareFixes(input.fixes, settings.gating, converter);
  if (prepared.fixes.empty())
    throw InputError(fmt::format(
        "{}: all {} GNSS fixes were gated: {} without a fix (status -1), {} with a reported "
        "horizontal sigma above georef.max_horizontal_sigma_m (--max-horizontal-sigma) {} m, {} "
        "with invalid values",
        gnss_name, prepared.total, prepared.gated_no_fix, prepared.gated_sigma,
        settings.gating.max_horizontal_sigma_m, prepared.gated_invalid));
  return prepared;
}

Association associate(const Trajectory& trajectory, const PreparedFixes& prepared,
                      const GeorefSettings& settings, const std::string& trajectory_name,
                      const std::string& gnss_name) {
  Association association = associateFixes(trajectory, prepared.fixes, settings.association);
  if (association.pairs.size() < 3)
    throw InputError(fmt::format(
        "{} (t {:.3f} to {:.3f} s) and the fixes of {} (t {:.3f} to {:.3f} s) overlap at only {} "
        "fix(es), at least 3 are needed ({} outside the trajectory's time span, {} in gaps "
        "longer than georef.max_gap_s (--max-gap) {} s); are both on the same clock?",
        trajectory_name, trajectory.startTime(), trajectory.endTime(), gnss_name,
        prepared.fixes.front().t_s, prepared.fixes.back().t_s, association.pairs.size(),
        association.outside_span, association.in_gap, settings.association.max_gap_s));
  return association;
}

GeorefFit fit(const Association& association, const GnssInput& input,
              const GeorefSettings& settings, const RigConfig& rig, const std::string& gnss_name) {
  switch (settings.method) {
    case GeorefMethod::kClosed:
      return fitClosed(association.pairs, settings.fit);
    case GeorefMethod::kPf3:
      return fitPf3(association.pairs, settings.fit);
    case GeorefMethod::kPf6: {
      if (!input.from_recording)
        throw InputError(fmt::format(
            "{}: georef method pf6 needs the IMU's absolute orientation, which a fixes CSV does not "
            "carry; give the recording, or use the robust or pf3 method",
            gnss_name));
      std::vector<double> times;
      for (const AssociatedFix& pair : association.pairs) times.push_back(pair.fix.t_s);
      const auto orientations =
          orientationsAt(absoluteOrientations(input.imu_with_orientation, rig.T_body_imu), times);
      try {
        return fitPf6(association.pairs, orientations, settings.fit);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}", gnss_name, e.what()));
      }
    }
    case GeorefMethod::kRobust:
      return fitRobust(association.pairs, settings.fit);
  }
  throw std::logic_error("georef: unknown method");
}

}  // namespace

GeorefSettings settingsFrom(const GeorefConfig& config) {
  GeorefSettings settings;
  settings.method = parseMethod(config.method);
  settings.epsg = config.epsg;
  settings.gating.max_horizontal_sigma_m = config.max_horizontal_sigma_m;
  settings.association.max_gap_s = config.max_gap_s;
  settings.association.p_body_antenna = config.p_body_antenna_m;
  settings.fit.error_correlation_time_s = config.error_correlation_time_s;
  return settings;
}

Georeference georeference(const Trajectory& trajectory, const GnssInput& input,
                          const GeorefSettings& settings, const RigConfig& rig,
                          const std::string& trajectory_name, const std::string& gnss_name) {
  if (trajectory.empty())
    throw InputError(fmt::format("{}: the trajectory has no poses", trajectory_name));
  const geo::CoordinateConverter converter(settings.epsg);  // InputError for unknown codes
  const PreparedFixes prepared = prepare(input, settings, converter, gnss_name);
  const Association association =
      associate(trajectory, prepared, settings, trajectory_name, gnss_name);

  Georeference out;
  GeorefReport& report = out.report;
  report.fit = fit(association, input, settings, rig, gnss_name);
  report.method = std::string(methodName(settings.method));
  report.epsg = converter.epsg();
  report.crs_name = converter.crsName();
  report.trajectory_file = trajectory_name;
  report.gnss_file = gnss_name;
  report.origin = prepared.origin;
  report.origin_grid = converter.toProjected(prepared.origin);
  report.T_epsg_world = tangentPlaneEpsgWorld(report.fit.T_enu_world, prepared.origin, converter);
  report.fixes_total = prepared.total;
  report.gated_no_fix = prepared.gated_no_fix;
  report.gated_sigma = prepared.gated_sigma;
  report.gated_invalid = prepared.gated_invalid;
  report.outside_span = association.outside_span;
  report.in_gap = association.in_gap;
  report.associated = association.pairs.size();
  out.poses = trajectoryInGrid(trajectory, report.fit.T_enu_world, prepared.origin, converter);
  out.fixes = association.pairs;
  return out;
}

void writeGeoreference(const std::filesystem::path& dir, const Georeference& georeference,
                       const std::string& trajectory_name) {
  std::filesystem::create_directories(dir);
  writeGridCsv(dir / fmt::format("trajectory_epsg{}.csv", georeference.report.epsg),
               georeference.poses);
  writeGeoJson(dir / "trajectory.geojson", georeference.poses, georeference.report.epsg,
               trajectory_name);
  writeGeorefYaml(dir / "georef.yaml", georeference.report);
  writeFixesCsv(dir / "fixes.csv", georeference.fixes, georeference.report.fit);
}

}  // namespace taiga::georef
