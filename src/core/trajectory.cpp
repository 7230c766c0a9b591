#include "taiga/core/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "taiga/core/errors.hpp"

namespace taiga {

Trajectory::Trajectory(std::vector<StampedPose> poses) {
  poses_.reserve(poses.size());
  for (const StampedPose& p : poses) append(p.t_s, p.pose);
}

void Trajectory::append(double t_s, const lie::SE3& pose) {
  if (!std::isfinite(t_s)) {
    throw std::invalid_argument(fmt::format("pose {} has a non-finite time", poses_.size()));
  }
  if (!poses_.empty() && !(t_s > poses_.back().t_s)) {
    throw std::invalid_argument(
        fmt::format("pose {} at t = {:.9f} s is not after the previous pose at t = {:.9f} s",
                    poses_.size(), t_s, poses_.back().t_s));
  }
  poses_.push_back({t_s, pose});
}

bool Trajectory::covers(double t_s) const {
  return !poses_.empty() && t_s >= startTime() && t_s <= endTime();
}

std::optional<lie::SE3> Trajectory::tryPoseAt(double t_s) const {
  if (!covers(t_s)) return std::nullopt;
  // First pose strictly after t_s; its predecessor is at or before t_s.
  const auto after = std::upper_bound(poses_.begin(), poses_.end(), t_s,
                                      [](double t, const StampedPose& p) { return t < p.t_s; });
  if (after == poses_.end()) return poses_.back().pose;  // t_s == endTime()
  const StampedPose& before = *(after - 1);
  const double s = (t_s - before.t_s) / (after->t_s - before.t_s);
  return lie::interpolate(before.pose, after->pose, s);
}

lie::SE3 Trajectory::poseAt(double t_s) const {
  if (auto pose = tryPoseAt(t_s)) return *pose;
  if (poses_.empty()) {
    throw OutOfRangeError(
        fmt::format("pose requested at t = {:.6f} s from an empty trajectory", t_s));
  }
  const double outside_s = t_s < startTime() ? startTime() - t_s : t_s - endTime();
  throw OutOfRangeError(fmt::format(
      "pose requested at t = {:.6f} s, {:.6f} s {} the trajectory span [{:.6f}, {:.6f}] s", t_s,
      outside_s, t_s < startTime() ? "before" : "after", startTime(), endTime()));
}

double Trajectory::pathLength() const {
  double length_m = 0.0;
  for (std::size_t i = 1; i < poses_.size(); ++i) {
    length_m += (poses_[i].pose.translation() - poses_[i - 1].pose.translation()).norm();
  }
  return length_m;
}

}  // namespace taiga
