#pragma once
// Synthetic georeferencing problems with a known T_enu_world: a loop walk in the world frame,
// fixes of the antenna in ENU with Gaussian noise from a fixed seed, optional multipath bursts.

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/georef/association.hpp"

namespace taiga::georef::test {

inline double deg(double degrees) { return degrees * kRadPerDeg; }

/// A 300 s walk at 10 Hz around a rounded loop of about 90 x 60 m that starts at the world
/// origin, heights over gentle terrain (+-2 m), heading along the path, small roll and pitch.
inline Trajectory loopWalk(double duration_s = 300.0) {
  Trajectory trajectory;
  for (int k = 0; k <= static_cast<int>(duration_s * 10.0); ++k) {
    const double t = 0.1 * k;
    const double phase = 2.0 * std::numbers::pi * t / duration_s;
    const Eigen::Vector3d p(45.0 * std::sin(phase) + 8.0 * std::sin(3.0 * phase),
                            30.0 * (1.0 - std::cos(phase)),
                            2.0 * std::sin(2.0 * phase) + 0.5 * std::sin(7.0 * phase));
    const double heading = std::atan2(30.0 * std::sin(phase),
                                      45.0 * std::cos(phase) + 24.0 * std::cos(3.0 * phase));
    const lie::SO3 R = lie::SO3::fromRollPitchYaw(deg(3.0) * std::sin(5.0 * phase),
                                                  deg(2.0) * std::cos(4.0 * phase), heading);
    trajectory.append(1000.0 + t, lie::SE3(R, p));
  }
  return trajectory;
}

struct NoiseModel {
  double sigma_horizontal_m = 0.5;
  double sigma_vertical_m = 1.0;
  /// 0: white noise; > 0: first-order Gauss-Markov errors with this correlation time, s.
  double correlation_time_s = 0.0;
  /// Share of fixes that start a multipath burst of `burst_fixes` fixes offset by `jump_m`.
  double multipath_share = 0.0;
  int burst_fixes = 3;
  Eigen::Vector3d jump_m = Eigen::Vector3d(18.0, -9.0, 12.0);
  unsigned seed = 7;
  /// The sigma of each fix swings by up to this share around the sigmas above, uniformly at
  /// random from fix to fix (canopy cover changing under a walker).
  double sigma_swing = 0.0;
  /// true: a fix's error is its own sigma times the (unit) Gauss-Markov state; false: the
  /// sigmas above times the state, whatever the fix's sigma (errors that do not follow it).
  bool errors_follow_sigma = true;
  /// Reported sigma / true sigma (< 1: an optimistic receiver).
  double reported_sigma_factor = 1.0;
  /// The reported sigma is further off by a factor exp(N(0, this^2)), independently per fix (a
  /// receiver's sigma is itself an estimate).
  double reported_sigma_noise = 0.0;
};

struct SyntheticFixes {
  std::vector<AssociatedFix> pairs;
  std::size_t multipath = 0;  ///< fixes moved by a multipath burst
  std::vector<bool> is_multipath;
};

/// Fixes at 1 Hz of the true antenna (body origin) positions T_enu_world * p_world, noisy.
inline SyntheticFixes synthesizeFixes(const Trajectory& trajectory, const lie::SE3& T_enu_world,
                                      const NoiseModel& noise) {
  std::mt19937_64 random(noise.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  SyntheticFixes out;
  int burst_left = 0;
  Eigen::Vector3d markov = Eigen::Vector3d::Zero();  // unit-variance Gauss-Markov state
  bool first = true;
  for (double t = trajectory.startTime() + 0.5; t < trajectory.endTime(); t += 1.0) {
    AssociatedFix pair;
    pair.T_world_body = trajectory.poseAt(t);
    pair.p_world = pair.T_world_body.translation();
    pair.fix.t_s = t;
    const Eigen::Vector3d white(gauss(random), gauss(random), gauss(random));
    if (noise.correlation_time_s > 0.0 && !first) {
      const double rho = std::exp(-1.0 / noise.correlation_time_s);  // fixes 1 s apart
      markov = rho * markov + std::sqrt(1.0 - rho * rho) * white;
    } else {
      markov = white;
    }
    first = false;
    // (No draw without a swing: the other tests keep their random sequences.)
    const double swing =
        noise.sigma_swing > 0.0 ? 1.0 + noise.sigma_swing * (2.0 * uniform(random) - 1.0) : 1.0;
    const double sigma_h = swing * noise.sigma_horizontal_m,
                 sigma_v = swing * noise.sigma_vertical_m;
    const double error_scale = noise.errors_follow_sigma ? swing : 1.0;
    const Eigen::Vector3d error(error_scale * noise.sigma_horizontal_m * markov.x(),
                                error_scale * noise.sigma_horizontal_m * markov.y(),
                                error_scale * noise.sigma_vertical_m * markov.z());
    pair.fix.p_enu = T_enu_world * pair.p_world + error;
    const double f =
        noise.reported_sigma_factor * (noise.reported_sigma_noise > 0.0
                                           ? std::exp(noise.reported_sigma_noise * gauss(random))
                                           : 1.0);
    pair.fix.covariance_enu_m2 =
        Eigen::Vector3d(f * f * sigma_h * sigma_h, f * f * sigma_h * sigma_h,
                        f * f * sigma_v * sigma_v)
            .asDiagonal();
    if (burst_left == 0 && uniform(random) < noise.multipath_share) burst_left = noise.burst_fixes;
    const bool jumped = burst_left > 0;
    if (jumped) {
      pair.fix.p_enu += noise.jump_m;
      --burst_left;
      ++out.multipath;
    }
    out.is_multipath.push_back(jumped);
    out.pairs.push_back(pair);
  }
  return out;
}

}  // namespace taiga::georef::test
