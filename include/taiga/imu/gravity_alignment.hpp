#pragma once
// Gravity and velocities from lidar poses and preintegrated IMU readings, for starting while
// moving (after the linear alignment of VINS-Mono, Qin et al., IEEE T-RO 2018, Sec. V-B, with
// metric lidar poses in place of up-to-scale visual ones, so no scale is estimated).
//
// Between consecutive poses k, k+1 (T_world_body from scan-to-map registration, in a world frame
// whose tilt is still unknown) the preintegrated increments satisfy ([Forster] Eq. 33):
//   p_{k+1} - p_k = v_k dt + 1/2 g dt^2 + R_k dp_k
//   v_{k+1} - v_k = g dt + R_k dv_k
// which is linear in the unknowns (v_0 .. v_N, g) and, with dp and dv to first order in the
// accelerometer bias, in b_a too. A first least-squares solve gives g's direction; a second, with
// |g| fixed to the local gravity, gives the velocities and the bias. The world frame is then
// re-levelled by the smallest rotation that turns g into (0, 0, -|g|), which leaves the heading
// unchanged.
//
// The bias is estimated, under a prior, because a horizontal bias and a tilt look alike: without
// it the alignment returns whatever bias the increments were integrated with, and a smoother run
// in the wrongly levelled frame puts part of that frame's tilt there (docs/odometry.md, "Starting
// without a start ritual"). Rotation of the rig tells them apart; without rotation the prior
// holds the bias.

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
  Vector3 accel_bias_mps2 = Vector3::Zero();  ///< the accelerometer bias, body frame
  double residual_rms = 0.0;              ///< of the second solve, m and m/s mixed
  /// Rotation that levels the frame: R_level * gravity_world = (0, 0, -|g|).
  lie::SO3 R_levelled_world;
};

/// What is known of the accelerometer bias before the alignment (per axis, body frame).
struct AccelBiasPrior {
  Vector3 mean_mps2 = Vector3::Zero();
  double sigma_mps2 = 0.1;
};

/// `poses` (N + 1 >= 3) and `increments` (N, increments[k] from pose k to pose k + 1).
/// Throws std::invalid_argument on mismatched sizes or a non-positive prior sigma.
GravityAlignment alignGravity(std::span<const lie::SE3> poses,
                              std::span<const Preintegrator> increments, double gravity_mps2,
                              const AccelBiasPrior& bias_prior);

}  // namespace taiga::imu
