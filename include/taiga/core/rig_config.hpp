#pragma once
// The sensor rig: where the lidar and the IMU sit on the body, and how their data must be read.
// See docs/frames.md for the frames and a picture.

#include "taiga/core/config.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga {

/// Unit of the IMU's acceleration output. Some drivers publish g instead of m/s^2.
enum class AccelerationUnit { kAuto, kMetersPerSecond2, kStandardGravity };

/// The gyroscope's scale-factor and axis errors (MEMS gyros: 0.5-1.5 % per axis, axes a few
/// tenths of a degree off): a reading is M_reading_true times the true rate plus the bias, all in
/// the IMU frame. Its rows are the gyro's x, y and z axes as built. Identity when unknown. The
/// Recording takes it out of every reading (docs/calibration.md, "The gyro's scale and axes").
struct GyroAxes final : ConfigSection {
  Eigen::Matrix3d M_reading_true = Eigen::Matrix3d::Identity();

  bool isIdentity() const { return M_reading_true == Eigen::Matrix3d::Identity(); }
  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

struct RigConfig final : ConfigSection {
  /// Pose of the lidar in the body frame: p_body = T_body_lidar * p_lidar.
  lie::SE3 T_body_lidar;
  /// Pose of the IMU in the body frame: p_body = T_body_imu * p_imu. Identity when the body
  /// frame is the IMU frame (the default).
  lie::SE3 T_body_imu;
  /// Added to every lidar time to express it on the IMU's clock, s.
  double lidar_time_offset_s = 0.0;
  /// Acceleration unit of the IMU; `auto` decides from the magnitude at rest.
  AccelerationUnit imu_acceleration_unit = AccelerationUnit::kAuto;
  /// Boxes in the body frame around parts of the rig that the lidar sees (the operator, a
  /// harvester's cabin): returns inside them are dropped before anything else.
  std::vector<Box> self_boxes_body;
  GyroAxes gyro_axes;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
