#pragma once
// Self-calibration of the rig (docs/calibration.md): the lidar-IMU time offset and extrinsic
// rotation estimated from the data, by `taiga calibrate` and at the start of `taiga run`.

#include "taiga/core/config.hpp"

namespace taiga {

struct CalibrationConfig final : ConfigSection {
  /// `taiga run` first calibrates on the recording's first stretch_s and runs with the result.
  /// On by default: a rig as users write it is off by degrees and milliseconds; a calibrated
  /// rig can switch it off.
  bool at_start = true;
  /// Length of the stretch calibrated on, s.
  double stretch_s = 30.0;
  /// A quantity whose 1-sigma exceeds these is not observable from the motion and stays as
  /// configured.
  double max_offset_sigma_s = 0.002;
  double max_rotation_sigma_deg = 0.1;
  double max_translation_sigma_m = 0.01;
  /// at_start: an odometry.imu.gyro_noise_density that the data show to be understated (a
  /// datasheet's figure; calib/gyro_noise.hpp) is replaced by the measured one for the run. A
  /// filter told the gyro is better than it is follows the gyro's scale errors through every
  /// turn (docs/calibration.md, "IMU noise").
  bool apply_gyro_noise = true;
  /// The lever arm's components that the motion shows (1-sigma within max_translation_sigma_m)
  /// and that changed by at least 3 sigma and 1 cm are applied; the rest stay as configured
  /// (docs/calibration.md, "Lever arm").
  bool apply_lever_arm = true;
  /// `taiga run` follows the lidar-IMU time offset through the run: a free-running lidar clock
  /// drifts against the IMU's by 10-50 ppm, 18 ms after 30 min at 10 ppm (pipeline/
  /// clock_tracker.hpp). Re-estimated every track_every_s from the last track_window_s of scans.
  bool track_offset = true;
  double track_window_s = 30.0;
  double track_every_s = 10.0;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
