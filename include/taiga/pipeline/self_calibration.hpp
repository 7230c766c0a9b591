#pragma once
// The rig's lidar-IMU time offset and extrinsic rotation from a stretch of a recording
// (docs/calibration.md): the lidar-inertial odometry runs over the stretch, its scan-to-map
// registrations give the body's rotation between scans, and calib::estimateTimeRotation compares
// them with the gyro. The registrations lean a little on the IMU (its prediction starts them,
// its propagation deskews the scan), so a wrong rig pulls them a little towards itself: each pass
// runs again with the rig the previous one found, until a pass changes nothing beyond its own
// 1-sigma (a wrong offset shrinks about fourfold per pass).
// When the first pass's registrations disagree with the gyro beyond noise (a gross mounting
// error, 90 or 180 deg, throws the IMU's prediction off), a lidar-only pass, which needs no rig,
// finds the mounting coarsely first. It is not the first pass always: at 10 Hz its
// constant-velocity deskew leaves errors of degrees per scan in a handheld's sway.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "taiga/calib/gyro_noise.hpp"
#include "taiga/calib/lever_arm.hpp"
#include "taiga/calib/time_rotation.hpp"
#include "taiga/core/system_config.hpp"

namespace taiga::pipeline {

struct SelfCalibrationOptions {
  double from_s = 0.0;      ///< start of the stretch, s after the recording's first scan
  double duration_s = 0.0;  ///< length of the stretch, s; 0: calibration.stretch_s
  int max_passes = 5;
};

struct CalibrationPass {
  std::string odometry = "lidar-inertial";  ///< or "lidar-only" (the coarse pass)
  std::size_t scans = 0;
  calib::TimeRotationEstimate estimate;  ///< relative to the pass's rig
  std::string failed;                    ///< why the pass gave no estimate; empty when it did
};

struct SelfCalibration {
  RigConfig rig;                     ///< the configured rig with the offset and rotation corrected
  double offset_change_s = 0.0;      ///< rig.lidar_time_offset_s minus the configured one
  lie::SO3 R_change;                 ///< R_body_lidar = R_change * R_body_lidar_configured
  calib::TimeRotationEstimate last;  ///< the last pass's estimate: its sigmas and observability
  /// The lever arm from the last pass; empty when it could not be estimated (lever_arm_failed
  /// says why). With calibration.apply_lever_arm the components in lever_arm_applied are added
  /// to `rig`'s translation (self_calibration.cpp, leverArmToApply).
  std::optional<calib::LeverArmEstimate> lever_arm;
  std::string lever_arm_failed;
  Eigen::Vector3<bool> lever_arm_applied{false, false, false};
  /// The gyro's noise density measured in the last pass (empty when the chains were too short)
  /// and what it says of the configured one (`taiga calibrate` writes the suggestion into its
  /// rig.yaml; `taiga run` uses it with calibration.apply_gyro_noise).
  std::optional<calib::GyroNoiseEstimate> gyro_noise;
  calib::NoiseVerdict gyro_noise_verdict;
  std::vector<CalibrationPass> passes;
  double from_s = 0.0, to_s = 0.0;  ///< the stretch used, recording time
};

/// The estimate with config.calibration's observability limits. Throws InputError when the
/// first pass gives no estimate (the message says why, e.g. no IMU,
/// too short a recording, or too few registrations that agree with the gyro).
SelfCalibration selfCalibrate(const std::filesystem::path& recording, const SystemConfig& config,
                              const SelfCalibrationOptions& options = {});

}  // namespace taiga::pipeline
