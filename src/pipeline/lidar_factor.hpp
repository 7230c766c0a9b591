#pragma once
// Step 5 of the odometry: judge a scan's registration to the local map and turn it into the
// lidar factor's pose measurement (thesis Eq. 36). Internal to the pipeline.

#include <optional>
#include <string>

#include "motion_prior.hpp"
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

/// `bound` grown with the time since the last scan the health monitor trusted, s: the IMU's dead
/// reckoning drifts with its square (lidar_factor.cpp).
JumpBound grownByDeadReckoning(const JumpBound& bound, double since_ok_s);

/// Rejected when the registration failed, its fitness is above max_fitness_m2, or (with a
/// `jump_bound`: the prediction comes from an IMU) it lies farther than the bound from
/// `predicted_T_odom_body`; inflated ten-fold when it did not converge or is degenerate; used
/// otherwise.
LidarFactorVerdict judgeRegistration(const registration::RegistrationResult& registration,
                                     const lie::SE3& predicted_T_odom_body,
                                     const std::optional<JumpBound>& jump_bound,
                                     const OdometryConfig& config);

}  // namespace taiga::pipeline
