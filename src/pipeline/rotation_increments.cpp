#include "taiga/pipeline/rotation_increments.hpp"

namespace taiga::pipeline {

bool measuredByLidar(const ScanOutcome& o) {
  return o.lidar == LidarFactor::kUsed && o.health.status != ScanStatus::kLost;
}

std::optional<calib::RotationIncrement> RotationIncrements::take(const ScanOutcome& o) {
  const lie::SO3& R_odom_body = o.registration.T_target_source.rotation();
  const bool follows = previous_ && previous_->measured && measuredByLidar(o) &&
                       o.scan_index == previous_->scan_index + 1 && !o.T_odom_unlevelled &&
                       o.imu_gap_s <= max_imu_gap_s_;
  std::optional<calib::RotationIncrement> increment;
  if (follows)
    increment = calib::RotationIncrement{previous_->t_s, o.t_s,
                                         (previous_->R_odom_body.inverse() * R_odom_body).Log()};
  previous_ = Previous{o.scan_index, o.t_s, measuredByLidar(o), R_odom_body};
  return increment;
}

}  // namespace taiga::pipeline
