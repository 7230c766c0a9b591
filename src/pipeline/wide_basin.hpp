#pragma once
// Lidar-only odometry's wide basin (docs/odometry.md, "Wide basin"): without an IMU the
// constant-velocity prediction can be 50 deg and a metre off at low scan rates (a handheld walk
// kept at 2 Hz), and NDT from there may settle in a wrong basin that still fits the map loosely.
// When the registration from the prediction overlaps the map less than the recent scans did, did
// not converge, or there is no such yardstick yet, a correlative search over heading and horizontal position
// (registration/correlative_search.hpp) proposes other starts; each is refined by the same NDT
// and the one whose points lie closest to the map wins. With an IMU the odometry asks for it only
// after a second without an ok scan (dead reckoning drifts: 0.7 m after 4 s blind), and keeps
// no yardstick then, so every such scan is searched. Internal to the pipeline.

#include <deque>
#include <functional>
#include <vector>

#include "health_monitor.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/pipeline/local_map.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::pipeline {

class WideBasin {
 public:
  using Align = std::function<registration::RegistrationResult(const lie::SE3& guess_T_odom_body)>;

  explicit WideBasin(const OdometryConfig& config);

  /// `first`, registered from the prediction `guess_T_odom_body`, or a clearly better
  /// registration from the correlative search's starts (each aligned with `align`).
  registration::RegistrationResult widen(const std::vector<Eigen::Vector3d>& source,
                                         const lie::SE3& guess_T_odom_body,
                                         registration::RegistrationResult first,
                                         const LocalMap& map, const HealthMonitor& health,
                                         const Align& align);
  /// The scan last registered was judged ok: its overlap joins the yardstick.
  void rememberLast();
  /// The local map started over: the yardstick does too.
  void forget() { recent_overlaps_.clear(); }

 private:
  /// Share of the source points within the overlap distance of the map's points.
  double overlap(const std::vector<Eigen::Vector3d>& source, const LocalMap& map,
                 const lie::SE3& T_odom_body) const;

  double overlap_distance_m_;
  double degenerate_condition_;
  std::deque<double> recent_overlaps_;
  double last_overlap_ = 0.0;
};

}  // namespace taiga::pipeline
