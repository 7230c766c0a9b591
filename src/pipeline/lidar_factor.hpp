#pragma once
// Step 5 of the odometry: judge a scan's registration to the local map and turn it into the
// lidar factor's pose measurement (thesis Eq. 36). Internal to the pipeline.

#include <optional>
#include <string>

#include "taiga/backend/odometry_smoother.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/pipeline/odometry.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::pipeline {

struct LidarFactorVerdict {
  LidarFactor factor = LidarFactor::kRejected;
  std::string note;  ///< why the factor was rejected or inflated
  /// T_odom_body with its covariance; none when rejected.
  std::optional<backend::PoseMeasurement> measurement;
};

/// Rejected when the registration failed, its fitness is above max_fitness_m2, or (with
/// `check_jump`: the prediction comes from an IMU, good to centimetres) it lies farther than
/// max_jump_m / max_jump_deg from `predicted_T_odom_body`; inflated ten-fold when it did not
/// converge or is degenerate; used otherwise.
LidarFactorVerdict judgeRegistration(const registration::RegistrationResult& registration,
                                     const lie::SE3& predicted_T_odom_body, bool check_jump,
                                     const OdometryConfig& config);

}  // namespace taiga::pipeline
