// taiga calibrate: the lidar-IMU time offset and extrinsic rotation from a stretch of a recording
// (pipeline/self_calibration.hpp, docs/calibration.md).
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/eval/plot.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/pipeline/self_calibration.hpp"
#include "taiga/pipeline/sweep_check.hpp"

namespace taiga::app {
namespace {
struct CalibrateOptions {
  std::string recording, config, out;
  pipeline::SelfCalibrationOptions calibration;
  bool plots = true;
};

Eigen::Vector3d degrees(const Eigen::Vector3d& rad) { return rad * kDegPerRad; }

std::vector<double> asVector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::vector<double> xyzw(const lie::SO3& R) {
  const Eigen::Quaterniond& q = R.quaternion();
  return {q.x(), q.y(), q.z(), q.w()};
}

/// The lever arm, and the axes along which rig.yaml got it (docs/calibration.md, "Lever arm").
nlohmann::json leverArmJson(const pipeline::SelfCalibration& c) {
  if (!c.lever_arm)
    return {{"estimated", false}, {"applied", false}, {"failed", c.lever_arm_failed}};
  const calib::LeverArmEstimate& e = *c.lever_arm;
  const Eigen::Vector3<bool>& applied = c.lever_arm_applied;
  return {{"estimated", true},
          {"applied", applied.any()},
          {"applied_along_body_xyz", std::vector<bool>{applied(0), applied(1), applied(2)}},
          {"change_m", asVector(e.correction_m)},
          {"sigma_m", asVector(e.sigma_m)},
          {"formal_sigma_m", asVector(e.formal_sigma_m)},
          {"jackknife_sigma_m", asVector(e.jackknife_sigma_m)},
          {"observable_along_body_xyz",
           std::vector<bool>{e.observable(0), e.observable(1), e.observable(2)}},
          {"note",
           "applied along an axis when observable and the change is at least 3 sigma and 1 cm: "
           "on registered poses the estimate is off by up to 1.2 cm even for a perfectly "
           "calibrated simulated rig (docs/calibration.md)"}};
}

/// The gyro's noise density against the lidar (calib/gyro_noise.hpp), with the residual's
/// variance per lag (the Allan-like curve it was fitted to).
nlohmann::json gyroNoiseJson(const SystemConfig& configured, const pipeline::SelfCalibration& c) {
  nlohmann::json j = {{"configured_radps_sqrthz", configured.odometry.imu.gyro_noise_density},
                      {"verdict", calib::toString(c.gyro_noise_verdict.kind)},
                      {"text", c.gyro_noise_verdict.text}};
  if (c.gyro_noise_verdict.suggested > 0.0)
    j["suggested_radps_sqrthz"] = c.gyro_noise_verdict.suggested;
  if (!c.gyro_noise) return j;
  const calib::GyroNoiseEstimate& e = *c.gyro_noise;
  j["measured_radps_sqrthz"] = e.density_radps_sqrthz;
  j["sigma_radps_sqrthz"] = e.density_sigma;
  j["rate_error_radps"] = e.rate_error_radps;
  j["registration_sigma_deg"] = e.registration_sigma_rad * kDegPerRad;
  const Eigen::Matrix3d& A = e.rate_error_matrix;
  j["rate_error_matrix"] = {asVector(A.row(0)), asVector(A.row(1)), asVector(A.row(2))};
  const Eigen::Matrix3d& D = e.rate_change_matrix_s;
  j["rate_change_matrix_s"] = {asVector(D.row(0)), asVector(D.row(1)), asVector(D.row(2))};
  nlohmann::json lags = nlohmann::json::array();
  for (const calib::LagVariance& l : e.lags)
    lags.push_back({{"lag_scans", l.lag_scans},
                    {"tau_s", l.tau_s},
                    {"variance_rad2", l.variance_rad2},
                    {"model_rad2", l.model_rad2},
                    {"samples", l.samples}});
  j["lags"] = lags;
  j["accelerometer"] =
      "not measured: its white noise moves the body by less than a millimetre over the lags the "
      "registrations resolve";
  return j;
}

nlohmann::json report(const std::string& recording, const SystemConfig& configured,
                      const pipeline::SelfCalibration& c) {
  const calib::TimeRotationEstimate& e = c.last;
  nlohmann::json j;
  j["kind"] = "calibration";
  j["recording"] = recording;
  j["stretch_s"] = {c.from_s, c.to_s};
  j["time_offset"] = {{"configured_s", configured.rig.lidar_time_offset_s},
                      {"estimated_s", c.rig.lidar_time_offset_s},
                      {"sigma_s", e.offset_sigma_s},
                      {"observable", e.offset_observable}};
  std::vector<bool> observable{e.rotation_observable(0), e.rotation_observable(1),
                               e.rotation_observable(2)};
  j["rotation"] = {{"configured_quaternion_xyzw", xyzw(configured.rig.T_body_lidar.rotation())},
                   {"estimated_quaternion_xyzw", xyzw(c.rig.T_body_lidar.rotation())},
                   {"change_deg", c.R_change.angle() * kDegPerRad},
                   {"change_rotation_vector_deg", asVector(degrees(c.R_change.Log()))},
                   {"sigma_deg", asVector(degrees(e.rotation_sigma_rad))},
                   {"observable_about_body_xyz", observable}};
  j["translation"] = leverArmJson(c);
  j["gyro_noise"] = gyroNoiseJson(configured, c);
  j["gyro_bias_radps"] = asVector(e.gyro_bias_radps);
  j["residual_rms_deg_s"] = e.residual_rms_radps * kDegPerRad;
  j["increments_used"] = e.increments_used;
  j["increments_dropped"] = e.increments_dropped;
  j["advice"] = e.advice;
  nlohmann::json passes = nlohmann::json::array();
  for (const pipeline::CalibrationPass& p : c.passes)
    passes.push_back({{"odometry", p.odometry},
                      {"scans", p.scans},
                      {"offset_change_s", p.failed.empty() ? p.estimate.offset_s : 0.0},
                      {"rotation_change_deg",
                       p.failed.empty() ? p.estimate.R_correction.angle() * kDegPerRad : 0.0},
                      {"failed", p.failed}});
  j["passes"] = passes;
  std::vector<double> offsets, rms;
  for (const calib::CostPoint& point : e.cost_curve) {
    offsets.push_back(point.offset_s);
    rms.push_back(point.rms_radps);
  }
  // The last pass's curve is over the change from that pass's rig; shown in absolute offsets.
  const double pass_offset_s = c.rig.lidar_time_offset_s - e.offset_s;
  for (double& offset : offsets) offset += pass_offset_s;
  j["cost_curve"] = {{"offset_s", offsets}, {"rms_radps", rms}};
  return j;
}

void writeCorrectedConfig(const std::filesystem::path& path, SystemConfig config,
                          const pipeline::SelfCalibration& c, const std::string& recording) {
  config.rig = c.rig;
  const bool noise = c.gyro_noise_verdict.kind == calib::NoiseVerdict::Kind::kUnderstated;
  if (noise) config.odometry.imu.gyro_noise_density = c.gyro_noise_verdict.suggested;
  std::ofstream out(path);
  out << fmt::format(
      "# Written by taiga calibrate from {} ({:.0f}-{:.0f} s): rig.lidar_time_offset_s and the\n"
      "# rotation of rig.T_body_lidar estimated, everything else (the lever arm too) as\n"
      "# configured{}. calibration.json has the values, their 1-sigma and what the motion "
      "showed.\n",
      recording, c.from_s, c.to_s,
      noise
          ? "\n# but odometry.imu.gyro_noise_density: measured, the configured one was understated"
          : "");
  out << io::writeConfigYaml(config);
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
}

int run(const CalibrateOptions& options) {
  SystemConfig config = loadConfig(options.config);
  validateAll(config);
  // Written into the corrected rig.yaml as recording.deskewed: true when the check finds it.
  const std::optional<pipeline::SweepCheck> sweep =
      pipeline::resolveDeskewed(options.recording, config);
  const pipeline::SelfCalibration c =
      pipeline::selfCalibrate(options.recording, config, options.calibration);
  const std::filesystem::path out(options.out);
  std::filesystem::create_directories(out);
  writeCorrectedConfig(out / "rig.yaml", config, c, options.recording);
  nlohmann::json j = report(options.recording, config, c);
  if (sweep) j["sweep_check"] = {{"verdict", pipeline::toString(sweep->verdict)},
                                 {"text", sweep->text}};
  std::ofstream(out / "calibration.json") << j.dump(2) << "\n";
  const calib::TimeRotationEstimate& e = c.last;
  fmt::print("stretch    {:.0f}-{:.0f} s, {} passes, {} scan-to-scan rotations used ({} dropped)\n",
             c.from_s, c.to_s, c.passes.size(), e.increments_used, e.increments_dropped);
  fmt::print(
      "offset     rig.lidar_time_offset_s {:.4f} s (change {:+.2f} ms, 1-sigma {:.2f} ms){}\n",
      c.rig.lidar_time_offset_s, 1e3 * c.offset_change_s, 1e3 * e.offset_sigma_s,
      e.offset_observable ? "" : ": not observable, kept as configured");
  const Eigen::Vector3d sigma_deg = degrees(e.rotation_sigma_rad);
  fmt::print(
      "rotation   R_body_lidar changed by {:.3f} deg (1-sigma {:.3f} {:.3f} {:.3f} deg about body "
      "x y "
      "z; observable about: {})\n",
      c.R_change.angle() * kDegPerRad, sigma_deg.x(), sigma_deg.y(), sigma_deg.z(),
      calib::axisNamesOrNone(e.rotation_observable));
  if (c.lever_arm)
    fmt::print(
        "lever arm  change {:.1f} {:.1f} {:.1f} cm (1-sigma {:.1f} {:.1f} {:.1f} cm); applied "
        "along: {} (at least 3 sigma and 1 cm; docs/calibration.md)\n",
        100 * c.lever_arm->correction_m.x(), 100 * c.lever_arm->correction_m.y(),
        100 * c.lever_arm->correction_m.z(), 100 * c.lever_arm->sigma_m.x(),
        100 * c.lever_arm->sigma_m.y(), 100 * c.lever_arm->sigma_m.z(),
        calib::axisNamesOrNone(c.lever_arm_applied));
  else
    fmt::print("lever arm  not estimated: {}\n", c.lever_arm_failed);
  fmt::print("gyro       bias {:.5f} {:.5f} {:.5f} rad/s; residual {:.3f} deg/s RMS\n",
             e.gyro_bias_radps.x(), e.gyro_bias_radps.y(), e.gyro_bias_radps.z(),
             e.residual_rms_radps * kDegPerRad);
  fmt::print("gyro noise {}{}\n", c.gyro_noise_verdict.text,
             c.gyro_noise_verdict.kind == calib::NoiseVerdict::Kind::kUnderstated
                 ? " (written into rig.yaml)"
                 : "");
  if (!e.advice.empty()) fmt::print("advice     {}\n", e.advice);
  if (options.plots) {
    const eval::PlotOutcome plots = eval::makePlots(j.dump(), out, "calibration_plot_data.json");
    if (!plots.ok) fmt::print("plots      not drawn: {}\n", plots.message);
  }
  fmt::print(
      "outputs    {}/ (rig.yaml: the configuration with the corrected rig, calibration.json{})\n",
      options.out, options.plots ? ", offset_cost.png" : "");
  const bool nothing = !e.offset_observable && !e.rotation_observable.any();
  return nothing ? kExitFailure : kExitOk;
}

}  // namespace

Command addCalibrateCommand(CLI::App& tool) {
  auto options = std::make_shared<CalibrateOptions>();
  CLI::App* parser = tool.add_subcommand(
      "calibrate",
      "Estimate the lidar-IMU time offset and extrinsic rotation from a stretch of a recording");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")
      ->required();
  addConfigOption(*parser, options->config);
  parser->add_option("--out", options->out, "Output directory")->required();
  parser
      ->add_option("--from", options->calibration.from_s,
                   "Start of the stretch, s after the first scan")
      ->check(CLI::NonNegativeNumber);
  parser
      ->add_option("--duration", options->calibration.duration_s,
                   "Length of the stretch, s (default: calibration.stretch_s, 30)")
      ->check(CLI::Range(5.0, 3600.0));
  parser->add_flag("!--no-plots", options->plots, "Do not draw offset_cost.png");
  return {parser, [options] { return run(*options); }, options};
}

}  // namespace taiga::app
