#include "taiga/mapping/trajectory_correction.hpp"

#include <algorithm>
#include <stdexcept>

namespace taiga::mapping {

Trajectory correctedTrajectory(const Trajectory& odometry, const PoseGraph& graph,
                               const std::vector<double>& keyframe_times_s) {
  if (keyframe_times_s.size() != graph.size())
    throw std::invalid_argument("correctedTrajectory: one time per graph keyframe");
  if (graph.size() == 0) return odometry;
  Trajectory corrections;
  for (std::size_t k = 0; k < graph.size(); ++k)
    corrections.append(keyframe_times_s[k], graph.pose(k) * graph.odometryPose(k).inverse());
  Trajectory corrected;
  for (const StampedPose& p : odometry) {
    const double t_s = std::clamp(p.t_s, corrections.startTime(), corrections.endTime());
    corrected.append(p.t_s, corrections.poseAt(t_s) * p.pose);
  }
  return corrected;
}

}  // namespace taiga::mapping
