// The constant-velocity motion model of lidar-only odometry (motion_prior.hpp).
#include "constant_velocity_prior.hpp"

#include <algorithm>

namespace taiga::pipeline {
namespace {

/// A walker's or a machine's roll and pitch sway about a mean at about 1 Hz: their rate
/// reverses within a quarter of that period.
constexpr double kSwayQuarterPeriod_s = 0.25;

}  // namespace

MotionPrediction ConstantVelocityPrior::predict(const io::Scan& scan) {
  Twist last = last_.value_or(Twist{scan.t_end_s});
  // The translation and the turn about the body's vertical are carried forward; the roll and
  // pitch rates fade with the time to predict over, gone at a quarter of the sway's period: over
  // a scan interval of 0.5 s the last rate predicts the wrong sign (measured on handheld walks
  // kept at 2 Hz: 10 deg of roll error where not extrapolating leaves 5), over 0.1 s it still
  // helps (10 Hz: carried in full, one registration of a 15 s walk was degenerate).
  const double dt_s = scan.t_end_s - last.t_s;
  last.twist_per_s.segment<2>(3) *= std::max(0.0, 1.0 - dt_s / kSwayQuarterPeriod_s);
  auto predictedAt = [&](double t_s) {
    return last.T_odom_body * lie::SE3::Exp(last.twist_per_s * (t_s - last.t_s));
  };
  MotionPrediction prediction;
  prediction.T_odom_body = predictedAt(scan.t_end_s);
  prediction.sweep_T_odom_body = sweepPoses(scan, predictedAt);
  prediction.constant_velocity = true;
  predicted_ = Twist{scan.t_end_s, prediction.T_odom_body};
  return prediction;
}

MotionUpdate ConstantVelocityPrior::update(const std::optional<backend::PoseMeasurement>& lidar) {
  // The registered pose where it was used, the prediction otherwise.
  const Twist last = last_.value_or(Twist{predicted_.t_s});
  const lie::SE3 T_odom_body = lidar ? lidar->T_world_body : predicted_.T_odom_body;
  const double dt = predicted_.t_s - last.t_s;
  last_ = Twist{predicted_.t_s, T_odom_body,
                dt > 0.0 ? lie::Vector6((last.T_odom_body.inverse() * T_odom_body).Log() / dt)
                         : lie::Vector6::Zero()};
  MotionUpdate update;
  update.state.T_odom_body = T_odom_body;
  update.state.v_odom = T_odom_body.rotation() * last_->twist_per_s.head<3>();
  // From the SE(3) tangent [rho; theta] at the pose to [dp (odom); dtheta]: dp = R rho to
  // first order.
  if (lidar) update.state.covariance = rotatedCovariance(lidar->covariance, T_odom_body.rotation());
  return update;
}

}  // namespace taiga::pipeline
