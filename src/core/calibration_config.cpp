#include "taiga/core/calibration_config.hpp"

namespace taiga {

void CalibrationConfig::visit(ConfigVisitor& v) {
  v.field("at_start", at_start,
          "true: taiga run first estimates rig.lidar_time_offset_s and the rotation of "
          "rig.T_body_lidar (and its lever arm, apply_lever_arm) on the recording's first "
          "stretch_s, then runs with them");
  v.field("stretch_s", stretch_s, "s of the recording calibrated on");
  v.field("max_offset_sigma_s", max_offset_sigma_s,
          "s; a time offset less certain than this is not observable and stays as configured");
  v.field("max_rotation_sigma_deg", max_rotation_sigma_deg,
          "deg; a rotation less certain than this about an axis stays as configured");
  v.field("max_translation_sigma_m", max_translation_sigma_m,
          "m; a lever arm less certain than this along a direction stays as configured");
  v.field("apply_gyro_noise", apply_gyro_noise,
          "true: at_start replaces an odometry.imu.gyro_noise_density that the data show to be "
          "understated by the measured one");
  v.field("apply_lever_arm", apply_lever_arm,
          "true: the lever arm's components found to change by at least 3 sigma and 1 cm are "
          "applied to rig.T_body_lidar");
  v.field("track_offset", track_offset,
          "true: taiga run keeps estimating rig.lidar_time_offset_s from its last track_window_s "
          "of scans and applies it (a lidar clock drifts against the IMU's)");
  v.field("track_window_s", track_window_s, "s of scans each re-estimate of the offset uses");
  v.field("track_every_s", track_every_s, "s between re-estimates of the offset");
}

void CalibrationConfig::validate() const {
  requireInRange("stretch_s", stretch_s, 5.0, 3600.0, "s");
  requireInRange("max_offset_sigma_s", max_offset_sigma_s, 1e-5, 0.1, "s");
  requireInRange("max_rotation_sigma_deg", max_rotation_sigma_deg, 0.001, 10.0, "deg");
  requireInRange("max_translation_sigma_m", max_translation_sigma_m, 0.0001, 1.0, "m");
  requireInRange("track_window_s", track_window_s, 5.0, 600.0, "s");
  requireInRange("track_every_s", track_every_s, 1.0, 600.0, "s");
}

}  // namespace taiga
