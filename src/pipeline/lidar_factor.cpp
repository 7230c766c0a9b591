#include "lidar_factor.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "taiga/core/angles.hpp"

namespace taiga::pipeline {
namespace {

std::string rejection(const registration::RegistrationResult& r,
                      const lie::SE3& predicted_T_odom_body,
                      const std::optional<JumpBound>& jump_bound, const OdometryConfig& config) {
  const lie::Vector6 jump = (predicted_T_odom_body.inverse() * r.T_target_source).Log();
  const double jump_m = jump.head<3>().norm(), jump_deg = jump.tail<3>().norm() / kRadPerDeg;
  if (r.iterations == 0 || r.num_inliers == 0 || !std::isfinite(r.hessian_condition))
    return "registration failed: " + r.reason;
  if (!std::isfinite(r.fitness_m2) || r.fitness_m2 > config.max_fitness_m2)
    return fmt::format("fitness {:.3f} m^2 above {:.3f}", r.fitness_m2, config.max_fitness_m2);
  if (jump_bound && (jump_m > jump_bound->max_m || jump_deg > jump_bound->max_deg))
    return fmt::format("{:.3f} m / {:.2f} deg from the IMU prediction", jump_m, jump_deg);
  return {};
}

/// Solution remapping (Zhang, Kaess and Singh 2016, "On degeneracy of optimization-based state
/// estimation problems"): the registration's step away from the prediction is kept along the
/// Hessian's eigenvectors that the scan constrains and dropped along those it does not
/// (eigenvalue below the largest / max_condition), where the prediction stands. `dropped` gets
/// the number of directions dropped.
lie::SE3 keepConstrainedDirections(const lie::SE3& predicted_T_odom_body,
                                   const registration::RegistrationResult& r, double max_condition,
                                   int& dropped) {
  const Eigen::SelfAdjointEigenSolver<lie::Matrix6> eigen(r.hessian);
  const lie::Vector6 step = (predicted_T_odom_body.inverse() * r.T_target_source).Log();
  const double floor = eigen.eigenvalues().maxCoeff() / max_condition;
  lie::Vector6 kept = lie::Vector6::Zero();
  dropped = 0;
  for (int i = 0; i < 6; ++i) {
    const lie::Vector6 direction = eigen.eigenvectors().col(i);
    if (eigen.eigenvalues()(i) > floor) {
      kept += direction * direction.dot(step);
    } else {
      ++dropped;
    }
  }
  return predicted_T_odom_body * lie::SE3::Exp(kept);
}

}  // namespace

JumpBound grownByDeadReckoning(const JumpBound& bound, double since_ok_s) {
  // Without a trusted scan (none arrived: a blocked view, lost packets; or they were distrusted)
  // the pose is the IMU's dead reckoning, whose error grows with the square of the time: an
  // attitude error of 1 deg leaks 0.17 m/s^2 of gravity into the acceleration, and a MEMS bias
  // left over is a few 0.01 m/s^2. After 4 s without scans (`harsh` IMU) the pose was 0.7 m
  // off, and the fixed bound rejected every scan that found it until the local map was given up.
  constexpr double kUnmodelledAccel_mps2 = 0.2;
  constexpr double kUnmodelledRate_dps = 0.5;  // gyro bias and scale errors left over in turns
  return {.max_m = bound.max_m + 0.5 * kUnmodelledAccel_mps2 * since_ok_s * since_ok_s,
          .max_deg = bound.max_deg + kUnmodelledRate_dps * since_ok_s};
}

LidarFactorVerdict judgeRegistration(const registration::RegistrationResult& r,
                                     const lie::SE3& predicted_T_odom_body,
                                     const std::optional<JumpBound>& jump_bound,
                                     const OdometryConfig& config) {
  LidarFactorVerdict verdict;
  verdict.note = rejection(r, predicted_T_odom_body, jump_bound, config);
  if (!verdict.note.empty()) return verdict;
  // Thesis Eq. 36 (OdometryConfig::lidarSigmas, docs/odometry.md), ten times wider when the
  // registration did not converge or is degenerate.
  double inflation = 1.0;
  verdict.factor = LidarFactor::kUsed;
  if (!r.converged || r.hessian_condition > config.degenerate_condition) {
    inflation = 10.0;
    verdict.factor = LidarFactor::kInflated;
    verdict.note = !r.converged
                       ? "registration hit its iteration limit"
                       : fmt::format("degenerate: Hessian condition {:.3g}", r.hessian_condition);
  }
  lie::SE3 T_odom_body = r.T_target_source;
  if (!jump_bound && r.hessian_condition > config.degenerate_condition &&
      std::isfinite(r.hessian_condition)) {
    // Without an IMU the prediction is a constant velocity and the measurement is taken as the
    // state whatever its covariance: the degenerate directions keep the prediction instead.
    int dropped = 0;
    T_odom_body =
        keepConstrainedDirections(predicted_T_odom_body, r, config.degenerate_condition, dropped);
    verdict.note +=
        fmt::format("; the prediction kept along {} direction{}", dropped, dropped == 1 ? "" : "s");
  }
  // Roll and pitch keep sigma_sm: gravity in the IMU factor observes them, and a tighter lidar
  // factor would hold on to a tilted local map. Heading has no such second source, so it gets its
  // own, tighter sigma (docs/odometry.md). The factor's rotation tangent is in the body frame:
  // Sigma_body = R^T Sigma_odom R.
  const LidarSigmas sigma = config.lidarSigmas(r.fitness_m2, inflation);
  const Eigen::Matrix3d R_odom_body = T_odom_body.rotation().matrix();
  const Eigen::Vector3d rotation_variances_odom(sigma.tilt_rad * sigma.tilt_rad,
                                                sigma.tilt_rad * sigma.tilt_rad,
                                                sigma.heading_rad * sigma.heading_rad);
  lie::Matrix6 covariance = lie::Matrix6::Zero();
  covariance.topLeftCorner<3, 3>() =
      Eigen::Matrix3d::Identity() * sigma.translation_m * sigma.translation_m;
  covariance.bottomRightCorner<3, 3>() =
      R_odom_body.transpose() * rotation_variances_odom.asDiagonal() * R_odom_body;
  verdict.measurement = backend::PoseMeasurement{T_odom_body, covariance};
  return verdict;
}

}  // namespace taiga::pipeline
