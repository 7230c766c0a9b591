#pragma once
// Measurements other than point clouds, as the readers deliver them. Times are double seconds on
// the recording's clock.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace taiga {

/// The frame an IMU's own orientation estimate refers to.
enum class OrientationReference {
  kEnu,      ///< x east, y north, z up (ROS REP-103)
  kNed,      ///< x north, y east, z down (many IMU vendors)
  kUnknown,  ///< e.g. gravity-aligned with an arbitrary heading; only roll and pitch are usable
};

/// Orientation reported by the IMU: q_reference_imu rotates vectors from the IMU frame into the
/// reference frame.
struct ImuOrientation {
  Eigen::Quaterniond q_reference_imu = Eigen::Quaterniond::Identity();
  OrientationReference reference = OrientationReference::kUnknown;
};

struct ImuSample {
  double t_s = 0.0;
  Eigen::Vector3d acceleration_imu_mps2 = Eigen::Vector3d::Zero();       ///< specific force, m/s^2
  Eigen::Vector3d angular_velocity_imu_radps = Eigen::Vector3d::Zero();  ///< rad/s
  std::optional<ImuOrientation> orientation;                             ///< absent for 6-axis IMUs
};

/// Fix quality, with the values of sensor_msgs/NavSatStatus.
enum class GnssStatus { kNoFix = -1, kFix = 0, kSbasFix = 1, kGbasFix = 2 };

/// How much of the covariance the receiver reported, with the values of sensor_msgs/NavSatFix.
enum class GnssCovarianceType { kUnknown = 0, kApproximated = 1, kDiagonalKnown = 2, kKnown = 3 };

struct GnssFix {
  double t_s = 0.0;
  double latitude_deg = 0.0;        ///< geodetic latitude, positive north
  double longitude_deg = 0.0;       ///< geodetic longitude, positive east
  double height_ellipsoid_m = 0.0;  ///< height above the ellipsoid (not above sea level)
  /// Position covariance in the local east-north-up frame at the fix, m^2.
  Eigen::Matrix3d covariance_enu_m2 = Eigen::Matrix3d::Identity();
  GnssCovarianceType covariance_type = GnssCovarianceType::kUnknown;
  GnssStatus status = GnssStatus::kNoFix;
};

}  // namespace taiga
