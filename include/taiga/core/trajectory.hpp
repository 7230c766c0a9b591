#pragma once
// Stamped poses and a trajectory that interpolates between them on SE(3).

#include <cstddef>
#include <optional>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace taiga {

/// A pose at a time. Which frames the pose relates is named by the variable holding it or the
/// trajectory it belongs to (e.g. `trajectory_world_body` holds T_world_body).
struct StampedPose {
  double t_s = 0.0;
  lie::SE3 pose;
};

class Trajectory {
 public:
  Trajectory() = default;
  /// Throws std::invalid_argument unless times are finite and strictly increasing.
  explicit Trajectory(std::vector<StampedPose> poses);

  /// Appends a pose after the last one; throws std::invalid_argument if t_s is not later.
  void append(double t_s, const lie::SE3& pose);

  std::size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }
  const StampedPose& operator[](std::size_t i) const { return poses_[i]; }
  const StampedPose& front() const { return poses_.front(); }
  const StampedPose& back() const { return poses_.back(); }
  auto begin() const { return poses_.begin(); }
  auto end() const { return poses_.end(); }
  const std::vector<StampedPose>& poses() const { return poses_; }

  double startTime() const { return poses_.front().t_s; }
  double endTime() const { return poses_.back().t_s; }
  /// True when t_s lies within [startTime(), endTime()].
  bool covers(double t_s) const;

  /// The pose at t_s, interpolated on the SE(3) geodesic between the neighbouring poses
  /// (thesis Eq. 34). Throws OutOfRangeError, with the time and the span, outside the span.
  lie::SE3 poseAt(double t_s) const;
  /// As poseAt(), but empty outside the span.
  std::optional<lie::SE3> tryPoseAt(double t_s) const;

  /// Length of the translational path, m.
  double pathLength() const;

 private:
  std::vector<StampedPose> poses_;
};

}  // namespace taiga
