#pragma once
// GNSS fixes into the mapping graph (issue 9 item 2, thesis Eq. 43): the part of the Mapper that
// turns geodetic fixes into GnssObservations of the PoseGraph.
//
// 1. Gate and convert (georef::prepareFixes, the post-fit's gating): fixes with no fix, invalid
//    values or a reported horizontal sigma above georef.max_horizontal_sigma_m are counted and
//    dropped; the others go to local ENU at the first fix that passes.
// 2. Attach by time: a fix waits until a keyframe at or after its time arrives; then the
//    odometry pose at the fix time is interpolated on SE(3) between the two bracketing
//    keyframes' odometry poses, and the fix is attached to the nearer of them with the antenna
//    (georef.p_body_antenna_m) in that keyframe's body frame (d_body). The residual so depends
//    on one keyframe only; the odometry between two keyframes (< 1 m apart) is far better than
//    GNSS. Interpolating in time assumes steady motion between keyframes. Fixes before the
//    first keyframe or after the last are not used.
// 3. Start: once gnss_min_fixes fixes are attached and the track spans gnss_min_spread_m
//    horizontally, T_enu_map starts from georef::fitRobust on them and every attached fix
//    becomes a factor; later fixes become factors as they are attached.
// 4. Weights: each fix is whitened by its reported covariance under a Huber kernel at
//    gnss_huber_sigmas, and its cost divided by the correlation factor
//    f = (1 + rho) / (1 - rho), rho = exp(-dt / tau) (dt: time since the previous fix, tau
//    georef.error_correlation_time_s): a long mean of Gauss-Markov errors has f times the
//    variance of a mean of white ones.
//
// Everything is driven by the order of the calls (fixes and keyframes), not by wall time.

#include <cstddef>
#include <optional>
#include <vector>

#include "taiga/core/georef_config.hpp"
#include "taiga/core/mapping_config.hpp"
#include "taiga/core/sensor_samples.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/fix_preparation.hpp"
#include "taiga/mapping/pose_graph.hpp"

namespace taiga::mapping {

/// What became of the fixes, and the estimate.
struct GnssFusionReport {
  std::size_t total = 0;          ///< fixes given
  std::size_t gated = 0;          ///< dropped by the quality gate (no fix, invalid, sigma)
  std::size_t outside = 0;        ///< before the first keyframe or after the last
  std::size_t waiting = 0;        ///< attached but not fused (fusion never started)
  std::size_t used = 0;           ///< factors in the graph
  std::size_t down_weighted = 0;  ///< factors beyond the Huber threshold at the final poses
  /// The ENU frame's origin (the first fix that passed the gate) and the estimated transform
  /// from the map into it (yaw and translation; none when fusion never started).
  std::optional<geo::Geodetic> enu_origin;
  std::optional<lie::SE3> T_enu_map;
};

class GnssFusion {
 public:
  /// The receiver's gate, error correlation time and antenna from `gnss` (the georef section).
  GnssFusion(const MappingConfig& config, const GeorefConfig& gnss);

  /// Gates the fix and queues it for attaching.
  void addFix(const GnssFix& fix);
  /// After the graph received keyframe `keyframe_times_s.size() - 1`: attaches the queued fixes
  /// up to its time, starts fusion when the fixes allow. Returns whether the graph has new GNSS
  /// factors that should be solved (paced by gnss_optimize_interval_s of recording time).
  bool afterKeyframe(PoseGraph& graph, const std::vector<double>& keyframe_times_s);
  /// End of the run: the queued fixes after the last keyframe are not used. Returns whether the
  /// graph has unsolved GNSS factors.
  bool finish(const PoseGraph& graph);
  GnssFusionReport report(const PoseGraph& graph) const;

 private:
  struct Attached {
    GnssObservation observation;
    double t_s;
  };
  void attach(const georef::LocalFix& fix, const PoseGraph& graph,
              const std::vector<double>& keyframe_times_s);
  void tryStart(PoseGraph& graph);

  MappingConfig config_;
  double correlation_time_s_;        ///< of the GNSS errors (GeorefConfig)
  Eigen::Vector3d p_body_antenna_m_;  ///< the antenna in the body frame (GeorefConfig)
  georef::FixGating gating_;
  geo::CoordinateConverter converter_;
  std::optional<geo::Geodetic> origin_;
  std::vector<georef::LocalFix> queued_;  ///< sorted by time
  std::vector<Attached> attached_;        ///< before fusion started
  std::optional<double> previous_fix_t_s_;
  std::optional<double> last_solve_t_s_;
  bool started_ = false;
  GnssFusionReport counts_;
};

}  // namespace taiga::mapping
