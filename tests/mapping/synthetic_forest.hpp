#pragma once
// A small deterministic forest for the loop closure tests: vertical stems (cylinders) on a ground
// with gentle relief, as points in the world frame, and scans of it from a pose (the points
// within range, thinned by a per-scan random draw so that no two scans hold the same points),
// in the body frame. Stems and relief depend on the seed: two seeds are two different places.

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::mapping::forest {

struct ForestOptions {
  double half_size_m = 25.0;  ///< the forest covers [-half_size_m, half_size_m]^2
  int stems = 40;
  double ground_spacing_m = 0.5;  ///< ground points on a grid this fine
  double stem_spacing_m = 0.25;   ///< stem points this far apart along the stem
  int stem_azimuths = 12;         ///< points around a stem at each height
};

/// About 10,000 ground points and 40 stems of a few hundred points each, in the world frame.
inline std::vector<Eigen::Vector3d> forestInWorld(unsigned seed,
                                                  const ForestOptions& options = {}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double phase_rad = 2.0 * std::numbers::pi * uniform(rng);
  const auto ground_z_m = [&](double x_m, double y_m) {
    return 0.4 * std::sin(0.35 * x_m + phase_rad) + 0.3 * std::cos(0.5 * y_m - phase_rad) +
           0.2 * std::sin(0.2 * (x_m + y_m));
  };
  std::vector<Eigen::Vector3d> points_in_world;
  const double half = options.half_size_m;
  // The grid is offset by a fraction of its spacing: on whole metres, its points would sit
  // exactly on the faces of NDT cells and voxels, where a registered point changes cell with the
  // last bit of its coordinates (no real scan is so regular).
  const double offset_m = 0.37 * options.ground_spacing_m;
  for (double x_m = -half + offset_m; x_m <= half; x_m += options.ground_spacing_m)
    for (double y_m = -half + offset_m; y_m <= half; y_m += options.ground_spacing_m)
      points_in_world.emplace_back(x_m, y_m, ground_z_m(x_m, y_m));
  for (int s = 0; s < options.stems; ++s) {
    const double x_m = -half + 2.0 * half * uniform(rng);
    const double y_m = -half + 2.0 * half * uniform(rng);
    const double radius_m = 0.12 + 0.18 * uniform(rng);
    const double height_m = 4.0 + 4.0 * uniform(rng);
    const double z0_m = ground_z_m(x_m, y_m);
    for (double h_m = 0.0; h_m <= height_m; h_m += options.stem_spacing_m)
      for (int a = 0; a < options.stem_azimuths; ++a) {
        const double azimuth_rad = 2.0 * std::numbers::pi * a / options.stem_azimuths;
        points_in_world.emplace_back(x_m + radius_m * std::cos(azimuth_rad),
                                     y_m + radius_m * std::sin(azimuth_rad), z0_m + h_m);
      }
  }
  return points_in_world;
}

/// The points of the forest within range_m (horizontally) of the sensor at T_world_body, each
/// kept with probability keep_fraction (drawn from `seed`), in the body frame.
inline PointCloud scanInBody(const std::vector<Eigen::Vector3d>& forest_in_world,
                             const lie::SE3& T_world_body, unsigned seed, double range_m = 18.0,
                             double keep_fraction = 0.5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const lie::SE3 T_body_world = T_world_body.inverse();
  PointCloud cloud_in_body;
  for (const Eigen::Vector3d& p_world : forest_in_world) {
    const bool kept = uniform(rng) < keep_fraction;  // one draw per point, kept or not
    if (!kept) continue;
    if ((p_world - T_world_body.translation()).head<2>().norm() > range_m) continue;
    cloud_in_body.positions.push_back(T_body_world * p_world);
  }
  return cloud_in_body;
}

/// A pose from a position (m) and a heading (yaw, rad).
inline lie::SE3 poseAt(double x_m, double y_m, double z_m, double yaw_rad) {
  return lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, yaw_rad), Eigen::Vector3d(x_m, y_m, z_m));
}

/// `keyframes` poses 1 m apart (counter-clockwise) on a circle of circumference
/// keyframes_per_lap m around the origin, 1.5 m above the ground, heading along the circle;
/// the first at (0, -r).
inline std::vector<lie::SE3> circlePath(int keyframes, int keyframes_per_lap = 40) {
  const double radius_m = keyframes_per_lap / (2.0 * std::numbers::pi);
  std::vector<lie::SE3> poses_T_world_body;
  for (int k = 0; k < keyframes; ++k) {
    const double angle_rad =
        2.0 * std::numbers::pi * k / keyframes_per_lap - 0.5 * std::numbers::pi;
    poses_T_world_body.push_back(poseAt(radius_m * std::cos(angle_rad),
                                        radius_m * std::sin(angle_rad), 1.5,
                                        angle_rad + 0.5 * std::numbers::pi));
  }
  return poses_T_world_body;
}

}  // namespace taiga::mapping::forest
