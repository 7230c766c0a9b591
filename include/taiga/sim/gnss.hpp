#pragma once
// Simulated GNSS receiver under canopy. The antenna sits at the body origin. The canopy cover
// above the antenna (share of 24 sky rays above 25 deg elevation that hit the scene) scales the
// error: 1-sigma horizontal = open + cover * canopy, vertical = factor * horizontal. The error is a
// first-order Gauss-Markov process (correlation time tau); multipath jumps of several to tens of
// metres start with probability p * cover and last a few fixes; outages drop fixes with
// probability p * cover. The reported covariance is the true sigma times a factor (< 1: the
// receiver is too optimistic, as real ones often are under trees).
//
// The world frame is the local east-north-up frame at (origin_latitude, origin_longitude,
// origin_height) on the WGS84 ellipsoid, turned by world_yaw_deg about up (0: world = ENU); fixes
// are converted exactly through ECEF.

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/sim/motion.hpp"
#include "taiga/sim/scenario.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

struct Geodetic {
  double latitude_deg = 0.0;
  double longitude_deg = 0.0;
  double height_m = 0.0;  ///< above the WGS84 ellipsoid
};

/// Local ENU coordinates (m) at `origin` to geodetic coordinates (WGS84), exact via ECEF.
Geodetic enuToGeodetic(const Geodetic& origin, const Eigen::Vector3d& p_enu);
/// The inverse of enuToGeodetic.
Eigen::Vector3d geodeticToEnu(const Geodetic& origin, const Geodetic& point);

class GnssSimulator {
 public:
  GnssSimulator(GnssParams params, std::uint64_t seed);

  /// Time of the next fix, motion time.
  double nextTime_s() const { return static_cast<double>(k_) / params_.rate_hz; }
  /// The next fix (or nothing during an outage); time is motion time + time_offset_s.
  std::optional<GnssFix> next(const WalkingMotion& motion, const Scene& scene,
                              double time_offset_s = 0.0);
  /// What the last fix drawn by next() really was (also for an outage).
  struct Truth {
    double t_s = 0.0;  ///< as the fix's stamp
    double sigma_horizontal_m = 0.0, sigma_vertical_m = 0.0;  ///< true 1-sigma
    Eigen::Vector3d error_enu_m = Eigen::Vector3d::Zero();     ///< multipath included
    bool multipath = false;
    bool outage = false;
  };
  const Truth& lastTruth() const { return truth_; }
  /// Canopy cover above a point, in [0, 1].
  static double canopyCover(const Scene& scene, const Eigen::Vector3d& p_world);
  Geodetic origin() const {
    return {params_.origin_latitude_deg, params_.origin_longitude_deg, params_.origin_height_m};
  }

 private:
  GnssParams params_;
  std::uint64_t seed_;
  std::uint64_t k_ = 0;
  Eigen::Vector3d markov_ = Eigen::Vector3d::Zero();  ///< unit-variance Gauss-Markov state
  Eigen::Vector3d jump_m_ = Eigen::Vector3d::Zero();
  int jump_fixes_left_ = 0;
  Truth truth_;
};

}  // namespace taiga::sim
