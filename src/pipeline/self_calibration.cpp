#include "taiga/pipeline/self_calibration.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "taiga/calib/gyro_noise.hpp"
#include "taiga/calib/lever_arm.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/pipeline/odometry.hpp"
#include "taiga/pipeline/rotation_increments.hpp"

namespace taiga::pipeline {
namespace {

struct PassData {
  std::vector<calib::RotationIncrement> increments;
  std::vector<calib::GyroReading> gyro;
  calib::LeverArmInput lever_arm;  ///< the registered poses in the levelled frame, the IMU
  std::size_t scans = 0;
};

/// The odometry over [from_s, to_s] of the recording (s after its first scan) with `rig`: the
/// registrations' rotation increments between consecutive measured scans, and the gyro readings
/// around them.
PassData runPass(const std::filesystem::path& path, const SystemConfig& config,
                 const RigConfig& rig, bool lidar_only, double from_s, double to_s,
                 double margin_s) {
  io::Recording recording = io::openRecording(path, config.recording, rig);
  Odometry odometry(config.odometry, rig, lidar_only);
  const Eigen::Matrix3d R_body_imu = rig.T_body_imu.rotation().matrix();
  PassData data;
  std::optional<double> first_scan_s;
  RotationIncrements increments(config.odometry.health.max_imu_gap_s);
  std::vector<std::vector<StampedPose>>& chains = data.lever_arm.chains;
  auto take = [&](const ScanOutcome& o) {
    const std::optional<calib::RotationIncrement> increment = increments.take(o);
    if (increment) data.increments.push_back(*increment);
    // Poses for the lever arm: only in the levelled frame, the levelling scan not included.
    if (o.T_odom_unlevelled) chains.clear();
    if (measuredByLidar(o) && !o.T_odom_unlevelled) {
      if (!increment || chains.empty()) chains.emplace_back();
      chains.back().push_back({o.t_s, o.registration.T_target_source});
    }
  };
  while (std::optional<io::RecordingEvent> event = recording.next()) {
    if (const auto* imu = std::get_if<ImuSample>(&*event)) {
      data.gyro.push_back({imu->t_s, R_body_imu * imu->angular_velocity_imu_radps});
      data.lever_arm.imu_body.push_back(
          {.t_s = imu->t_s,
           .acceleration_imu_mps2 = R_body_imu * imu->acceleration_imu_mps2,
           .angular_velocity_imu_radps = data.gyro.back().omega_body_radps});
      if (!lidar_only) odometry.addImu(*imu);
      if (first_scan_s && imu->t_s > *first_scan_s + to_s + margin_s) break;
    } else if (const auto* scan = std::get_if<io::Scan>(&*event)) {
      if (!first_scan_s) first_scan_s = scan->t_end_s;
      const double t_s = scan->t_end_s - *first_scan_s;
      if (t_s < from_s || t_s > to_s) continue;
      ++data.scans;
      for (const ScanOutcome& o : odometry.addScan(*scan)) take(o);
    }
  }
  data.lever_arm.gravity_odom_mps2 = {0.0, 0.0, -config.odometry.imu.gravity_mps2};
  data.lever_arm.noise = config.odometry.imu;
  return data;
}

/// The rig with a pass's estimate applied.
RigConfig corrected(RigConfig rig, const calib::TimeRotationEstimate& e) {
  rig.lidar_time_offset_s += e.offset_s;
  rig.T_body_lidar =
      lie::SE3(e.R_correction * rig.T_body_lidar.rotation(), rig.T_body_lidar.translation());
  return rig;
}

std::string describe(const calib::TimeRotationEstimate& e) {
  return fmt::format(
      "offset {:+.2f} ms (1-sigma {:.2f}{}), rotation {:.3f} deg (1-sigma {:.3f} deg, observable "
      "about {} axes), residual {:.2f} deg/s, {} increments",
      1e3 * e.offset_s, 1e3 * e.offset_sigma_s, e.offset_observable ? "" : ", not observable",
      e.R_correction.angle() * kDegPerRad, e.rotation_sigma_rad.maxCoeff() * kDegPerRad,
      e.rotation_observable.count(), e.residual_rms_radps * kDegPerRad, e.increments_used);
}

/// The registrations' rotations agree with the gyro's by less than half their size: not noise but
/// a rig too wrong for the IMU to start them (or a gross error of the gyro's frame). Only a rig
/// that turns can show it: when it barely turns, its rotation rates are the size of the
/// registrations' noise (0.2-0.3 deg/s on a harvester that stands and drives straight), and the
/// lidar-only pass then "found" a 14 deg mounting error about axes it could not see.
bool disagrees(const calib::TimeRotationEstimate& e) {
  constexpr double kMinSignal_radps = 1.0 * kRadPerDeg;
  return e.signal_rms_radps > kMinSignal_radps && e.residual_rms_radps > 0.5 * e.signal_rms_radps;
}

/// A pass that moved nothing beyond its own 1-sigma: the estimate has converged.
bool settled(const calib::TimeRotationEstimate& e) {
  const Eigen::Vector3d theta = e.R_correction.Log();
  return std::abs(e.offset_s) <= e.offset_sigma_s &&
         (theta.cwiseAbs().array() <= e.rotation_sigma_rad.array()).all();
}

/// The lever arm from the last pass's poses (with the rotation and offset it ran with).
void estimateLeverArm(PassData& data, double max_sigma_m, SelfCalibration& result) {
  data.lever_arm.bias_hat.gyro_radps = result.last.gyro_bias_radps;
  try {
    result.lever_arm = calib::estimateLeverArm(data.lever_arm, max_sigma_m);
  } catch (const InputError& e) {
    result.lever_arm_failed = e.what();
  }
}

/// The components of the lever arm's change worth applying: observable, at least 3 sigma, and
/// at least 1 cm. On registered poses the estimate of a perfectly calibrated simulated rig is
/// off by up to 1.2 cm, several sigma on some walks (docs/calibration.md, "Lever arm"), so a
/// smaller change is not told from that bias; a rig measured from a drawing is off by a few cm.
Eigen::Vector3<bool> leverArmToApply(const calib::LeverArmEstimate& e) {
  constexpr double kBias_m = 0.01;
  Eigen::Vector3<bool> apply;
  for (int k = 0; k < 3; ++k) {
    const double change_m = std::abs(e.correction_m[k]);
    apply[k] = e.observable[k] && change_m >= 3.0 * e.sigma_m[k] && change_m >= kBias_m;
  }
  return apply;
}

void applyLeverArm(SelfCalibration& result) {
  const calib::LeverArmEstimate& e = *result.lever_arm;
  result.lever_arm_applied = leverArmToApply(e);
  const Eigen::Vector3d change_m = result.lever_arm_applied.select(e.correction_m, 0.0);
  const lie::SE3& T = result.rig.T_body_lidar;
  result.rig.T_body_lidar = lie::SE3(T.rotation(), T.translation() + change_m);
}

/// The gyro's noise density from the last pass's registrations against the gyro, judged against
/// the configured one (the configuration's noise is what the odometry trusts).
void estimateGyroNoise(const PassData& data, double configured, SelfCalibration& result) {
  try {
    const calib::GyroNoiseEstimate e =
        calib::estimateGyroNoise({.chains = data.lever_arm.chains,
                                  .gyro = data.gyro,
                                  .offset_s = result.last.offset_s,
                                  .R_correction = result.last.R_correction,
                                  .bias_radps = result.last.gyro_bias_radps});
    result.gyro_noise_verdict = calib::judgeGyroNoise(e, configured);
    logger().info("calibration: {}", result.gyro_noise_verdict.text);
    result.gyro_noise = e;
  } catch (const InputError& e) {
    result.gyro_noise_verdict.text = fmt::format("gyro noise density not measured: {}", e.what());
  }
}

}  // namespace

SelfCalibration selfCalibrate(const std::filesystem::path& recording, const SystemConfig& config,
                              const SelfCalibrationOptions& options) {
  SelfCalibration result;
  result.rig = config.rig;
  result.from_s = options.from_s;
  result.to_s = options.from_s +
                (options.duration_s > 0.0 ? options.duration_s : config.calibration.stretch_s);
  const calib::TimeRotationOptions estimator{
      .max_offset_sigma_s = config.calibration.max_offset_sigma_s,
      .max_rotation_sigma_rad = config.calibration.max_rotation_sigma_deg * kRadPerDeg};
  const double margin_s = estimator.max_offset_s + 0.5;
  PassData last_data;
  auto pass = [&](bool lidar_only, const calib::TimeRotationOptions& limits) {
    CalibrationPass p{.odometry = lidar_only ? "lidar-only" : "lidar-inertial"};
    try {
      PassData data =
          runPass(recording, config, result.rig, lidar_only, result.from_s, result.to_s, margin_s);
      p.scans = data.scans;
      if (data.gyro.empty())
        throw InputError("the recording has no IMU readings in the stretch: nothing to calibrate");
      p.estimate = calib::estimateTimeRotation(data.increments, data.gyro, limits);
      if (!lidar_only) last_data = std::move(data);
    } catch (const InputError& e) {
      p.failed = e.what();
    }
    logger().info("calibration pass {} ({}): {}", result.passes.size() + 1, p.odometry,
                  p.failed.empty() ? describe(p.estimate) : p.failed);
    result.passes.push_back(p);
    return p;
  };
  for (int i = 0; i < options.max_passes; ++i) {
    CalibrationPass p = pass(false, estimator);
    if (i > 0 && !p.failed.empty()) break;  // keep the previous pass's rig
    // The first pass's registrations disagree with the gyro, or too few of them worked: a rig
    // too wrong for the IMU's prediction to start them.
    if (i == 0 && (!p.failed.empty() || disagrees(p.estimate))) {
      // Coarse: the rotation only, whatever its sigma (degrees are enough for the IMU's
      // prediction to start the registrations again).
      calib::TimeRotationOptions coarse = estimator;
      coarse.max_rotation_sigma_rad = 0.1;
      coarse.max_offset_sigma_s = 0.0;
      const CalibrationPass c = pass(true, coarse);
      if (c.failed.empty()) {
        result.rig = corrected(result.rig, c.estimate);
        continue;
      }
      if (!p.failed.empty())
        throw InputError(fmt::format("{}: calibration failed: {}", recording.string(), p.failed));
    }
    result.rig = corrected(result.rig, p.estimate);
    result.last = p.estimate;
    if (settled(p.estimate)) break;
  }
  if (disagrees(result.last))
    result.last.advice = fmt::format(
        "the registrations and the gyro disagree beyond noise ({:.1f} deg/s RMS against a "
        "signal of {:.1f} deg/s): check rig.T_body_lidar and rig.T_body_imu for a gross error (a "
        "90 or 180 deg mounting, swapped axes); {}",
        result.last.residual_rms_radps * kDegPerRad, result.last.signal_rms_radps * kDegPerRad,
        result.last.advice);
  estimateLeverArm(last_data, config.calibration.max_translation_sigma_m, result);
  if (result.lever_arm && config.calibration.apply_lever_arm) applyLeverArm(result);
  if (result.lever_arm) {
    const calib::LeverArmEstimate& e = *result.lever_arm;
    logger().info(
        "calibration: lever arm change {:.1f} {:.1f} {:.1f} cm (1-sigma {:.1f} {:.1f} {:.1f} cm); "
        "applied along: {}",
        100 * e.correction_m.x(), 100 * e.correction_m.y(), 100 * e.correction_m.z(),
        100 * e.sigma_m.x(), 100 * e.sigma_m.y(), 100 * e.sigma_m.z(),
        calib::axisNamesOrNone(result.lever_arm_applied));
  }
  estimateGyroNoise(last_data, config.odometry.imu.gyro_noise_density, result);
  result.offset_change_s = result.rig.lidar_time_offset_s - config.rig.lidar_time_offset_s;
  result.R_change =
      result.rig.T_body_lidar.rotation() * config.rig.T_body_lidar.rotation().inverse();
  return result;
}

}  // namespace taiga::pipeline
