#pragma once
// Gravity and velocities from lidar poses and preintegrated IMU readings, for starting while
// moving (after the linear alignment of VINS-Mono, Qin et al., IEEE T-RO 2018, Sec. V-B, with
// metric lidar poses in place of up-to-scale visual ones, so no scale is estimated).
//
// Between consecutive poses k, k+1 (T_world_body from scan-to-map registration, in a world frame
// whose tilt is still unknown) the preintegrated increments satisfy ([Forster] Eq. 33):
//   p_{k+1} - p_k = v_k dt + 1/2 g dt^2 + R_k dp_k
//   v_{k+1} - v_k = g dt + R_k dv_k
// which is linear in the unknowns (v_0 .. v_N, g). A first least-squares solve gives g's
// direction; a second, with |g| fixed to the local gravity, gives the velocities. The world
// frame is then re-levelled by the smallest rotation that turns g into (0, 0, -|g|), which
// leaves the heading unchanged.
//
// Optionally the accelerometer bias b_a is a further unknown (the increments then taken at
// b_a = 0 and corrected by dp + dP/dba b_a, dv + dV/dba b_a), under a prior N(0, sigma^2), and
// g's direction is refined with |g| fixed (VINS-Mono Sec. V-B3). A horizontal bias and a tilt
// differ only once the rig has turned about the vertical; the prior decides the rest.

#include <span>
#include <vector>

#include "taiga/imu/preintegration.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::imu {

struct GravityAlignment {
  Vector3 gravity_world =
      Vector3::Zero();                    ///< in the frame of the poses, |g| = the given magnitude
  double estimated_magnitude_mps2 = 0.0;  ///< |g| of the free first solve: a check of the data
  std::vector<Vector3> v_world;           ///< velocity at each pose
  Vector3 accel_bias_mps2 = Vector3::Zero();  ///< in the body frame, when estimated
  double residual_rms = 0.0;                  ///< of the final solve's data rows, m and m/s mixed
  /// Rotation that levels the frame: R_level * gravity_world = (0, 0, -|g|).
  lie::SO3 R_levelled_world;
};

/// `poses` (N + 1 >= 3) and `increments` (N, increments[k] from pose k to pose k + 1).
/// `accel_bias_sigma_mps2` > 0: the accelerometer bias is estimated under that prior; 0: the
/// increments' own bias is taken as exact. Throws std::invalid_argument on mismatched sizes.
GravityAlignment alignGravity(std::span<const lie::SE3> poses,
                              std::span<const Preintegrator> increments, double gravity_mps2,
                              double accel_bias_sigma_mps2 = 0.0);

}  // namespace taiga::imu
