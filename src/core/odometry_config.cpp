#include "taiga/core/odometry_config.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace taiga {

void ImuNoiseConfig::visit(ConfigVisitor& v) {
  v.field("accel_noise_density", accel_noise_density, "m/s^2/sqrt(Hz), accelerometer white noise");
  v.field("gyro_noise_density", gyro_noise_density, "rad/s/sqrt(Hz), gyroscope white noise");
  v.field("accel_bias_random_walk", accel_bias_random_walk,
          "m/s^3/sqrt(Hz), accelerometer bias random walk");
  v.field("gyro_bias_random_walk", gyro_bias_random_walk,
          "rad/s^2/sqrt(Hz), gyroscope bias random walk");
  v.field("gravity_mps2", gravity_mps2, "m/s^2, local gravity magnitude");
}

void ImuNoiseConfig::validate() const {
  requirePositive("accel_noise_density", accel_noise_density, "m/s^2/sqrt(Hz)");
  requirePositive("gyro_noise_density", gyro_noise_density, "rad/s/sqrt(Hz)");
  requirePositive("accel_bias_random_walk", accel_bias_random_walk, "m/s^3/sqrt(Hz)");
  requirePositive("gyro_bias_random_walk", gyro_bias_random_walk, "rad/s^2/sqrt(Hz)");
  requireInRange("gravity_mps2", gravity_mps2, 9.7, 9.9, "m/s^2");
}

void HealthConfig::visit(ConfigVisitor& v) {
  v.field("lost_after_s", lost_after_s,
          "s without a scan judged ok (dead reckoning only) after which the track is lost");
  v.field("lost_after_scans", lost_after_scans,
          "scans in a row not ok that also need to pass before the track is lost");
  v.field("reinitialize_after_s", reinitialize_after_s,
          "s lost beyond lost_after_s after which the local map starts over from the next scan");
  v.field("recovery_scans", recovery_scans, "scans judged ok in a row that end a lost stretch");
  v.field("history_scans", history_scans,
          "recent ok scans whose median fitness and inlier share are the yardstick");
  v.field("fitness_ratio", fitness_ratio,
          "a scan whose fitness is above this many times the recent median is degraded");
  v.field("fitness_floor_m2", fitness_floor_m2,
          "m^2, fitness below this is never degraded (noise level)");
  v.field("inlier_share_ratio", inlier_share_ratio,
          "a scan whose inlier share is below this fraction of the recent median is degraded");
  v.field("max_speed_mps", max_speed_mps, "m/s, a faster estimate means the track is lost");
  v.field("max_acceleration_mps2", max_acceleration_mps2,
          "m/s^2, a faster change of the estimated velocity between scans is degraded");
  v.field("max_accel_bias_mps2", max_accel_bias_mps2,
          "m/s^2, an accelerometer bias estimate beyond this is implausible: degraded");
  v.field("max_gyro_bias_dps", max_gyro_bias_dps,
          "deg/s, a gyroscope bias estimate beyond this is implausible: degraded");
  v.field("max_median_innovation_deg", max_median_innovation_deg,
          "deg, with an IMU: a median rotation between the IMU prediction and the registration "
          "above this over the run flags the rig's calibration or IMU noise settings as suspect");
  v.field("sparse_scan_ratio", sparse_scan_ratio,
          "scans with fewer points after the voxel filter than this fraction of the run's median "
          "are reported as sparse (lost packets, a blocked view)");
  v.field("max_imu_gap_s", max_imu_gap_s,
          "s, with an IMU: a scan after a longer stretch without IMU readings is degraded and the "
          "IMU factor over the gap weakened");
}

void HealthConfig::validate() const {
  requireInRange("lost_after_s", lost_after_s, 0.05, 60.0, "s");
  requireInRange("lost_after_scans", lost_after_scans, 1, 1000, "scans");
  requireInRange("reinitialize_after_s", reinitialize_after_s, 0.0, 3600.0, "s");
  requireInRange("recovery_scans", recovery_scans, 1, 1000, "scans");
  requireInRange("history_scans", history_scans, 3, 10000, "scans");
  requireInRange("fitness_ratio", fitness_ratio, 1.0, 1000.0, "");
  requireNonNegative("fitness_floor_m2", fitness_floor_m2, "m^2");
  requireInRange("inlier_share_ratio", inlier_share_ratio, 0.0, 1.0, "");
  requirePositive("max_speed_mps", max_speed_mps, "m/s");
  requirePositive("max_acceleration_mps2", max_acceleration_mps2, "m/s^2");
  requirePositive("max_accel_bias_mps2", max_accel_bias_mps2, "m/s^2");
  requirePositive("max_gyro_bias_dps", max_gyro_bias_dps, "deg/s");
  requirePositive("max_median_innovation_deg", max_median_innovation_deg, "deg");
  requirePositive("max_imu_gap_s", max_imu_gap_s, "s");
  requireInRange("sparse_scan_ratio", sparse_scan_ratio, 0.0, 1.0, "");
}

void OdometryConfig::visit(ConfigVisitor& v) {
  v.field("min_range_m", min_range_m, "m, returns closer to the lidar are dropped (operator, rig)");
  v.field("max_range_m", max_range_m, "m, returns farther from the lidar are dropped");
  v.field("voxel_size_m", voxel_size_m, "m, voxel filter of the scan registered to the local map");
  static constexpr std::array<std::string_view, 2> kVoxelPoints{"centroid", "measured"};
  v.choice("voxel_point", voxel_point, kVoxelPoints,
           "the point that stands for each voxel of the registered scan: centroid, or measured "
           "(the return nearest the voxel's mean: less shrink of the trajectory, but not yet "
           "robust in re-attachment; docs/registration.md, Bias)");
  static constexpr std::array<std::string_view, 3> kImuUses{"auto", "lidar_inertial", "lidar_only"};
  v.choice(
      "imu_use", imu_use, kImuUses,
      "lidar_only: constant-velocity prediction and deskew, no IMU; auto: lidar_only when no IMU "
      "reading comes within the first 2 s of scans");
  static constexpr std::array<std::string_view, 3> kMethods{"ndt", "d2d", "gicp"};
  v.choice("method", method, kMethods,
           "scan-to-map registration: ndt, d2d (distribution-to-distribution) or gicp");
  v.field("ndt_resolution_m", ndt_resolution_m,
          "m, NDT cell size of the local map; 0.5 for 64 beams or more (docs/odometry.md, Scale)");
  v.field("ndt_coarse_resolution_m", ndt_coarse_resolution_m,
          "m, cells of a first, coarser NDT pass without an IMU, for the first two scans and in "
          "loop closure; 0 or not coarser than ndt_resolution_m: none");
  static constexpr std::array<std::string_view, 2> kNeighbours{"direct1", "direct7"};
  v.choice("ndt_neighbours", ndt_neighbours, kNeighbours,
           "NDT cells each scan point is scored against: its own (direct1) or also the six face "
           "neighbours (direct7)");
  v.field("ndt_stem_cells", ndt_stem_cells,
          "true: NDT cells holding a stem's section score points by their distance to its "
          "circle, the same from every side (half the shrink; docs/registration.md, Bias)");
  v.field("ndt_stem_cells_across_borders", ndt_stem_cells_across_borders,
          "true: a cell whose own part of a stem is too short for a circle takes the circle of a "
          "2 x 2 block of cells around it (a stem cut by cell borders; slightly less shrink, but "
          "IMU-gap bridging diverged with it; docs/registration.md, Bias)");
  v.field("ndt_stem_cells_range_noise", ndt_stem_cells_range_noise,
          "true: the stem cells' circles are fitted with the local map's range noise "
          "(lidar_range_sigma_m, lidar_range_sigma_per_m) taken out along each point's beam "
          "(docs/registration.md, Range noise in the stem cells)");
  v.field("lidar_range_sigma_m", lidar_range_sigma_m,
          "m, the lidar's range noise (1-sigma) near the sensor, as its datasheet's precision");
  v.field("lidar_range_sigma_per_m", lidar_range_sigma_per_m,
          "the range noise's growth per metre of range (1-sigma: lidar_range_sigma_m + this x "
          "range)");
  v.field("local_map_voxel_m", local_map_voxel_m, "m, spacing of keyframe points in the local map");
  static constexpr std::array<std::string_view, 2> kLocalMapPoints{"centroid", "bearing"};
  v.choice("local_map_point", local_map_point, kLocalMapPoints,
           "the point that stands for each local-map voxel of a keyframe: centroid, or bearing "
           "(the return whose direction from the lidar is nearest the centroid's: on a stem's "
           "surface, not inside it; docs/registration.md, Bias)");
  v.field("local_map_keyframes", local_map_keyframes, "keyframes held in the local map");
  v.field("lidar_sigma", lidar_sigma,
          "m and rad, sigma of the lidar factor at good fitness (thesis sigma_sm)");
  v.field("lidar_heading_sigma_rad", lidar_heading_sigma_rad,
          "rad, sigma of the lidar factor's heading (about the vertical) at good fitness; 0: "
          "lidar_sigma (the thesis uses one sigma for all six axes)");
  v.field("fitness_threshold_m2", fitness_threshold_m2,
          "m^2, fitness above which the sigma grows (thesis tau_fs)");
  v.field("fitness_sigma_exponent", fitness_sigma_exponent,
          "exponent of that growth (thesis theta_smsc)");
  v.field("max_fitness_m2", max_fitness_m2, "m^2, registrations with a worse fitness are not used");
  v.field("max_jump_m", max_jump_m,
          "m, registrations further from the IMU prediction are not used");
  v.field("max_jump_deg", max_jump_deg,
          "deg, registrations rotated further from the IMU prediction are not used");
  v.field("degenerate_condition", degenerate_condition,
          "Hessian condition number above which the lidar factor is inflated");
  v.field("keyframe_distance_m", keyframe_distance_m,
          "m, weighted travelled distance between keyframes");
  v.field("keyframe_rotation_weight_m_per_rad", keyframe_rotation_weight_m_per_rad,
          "m/rad, weight of rotation in the travelled distance");
  v.field("window_states", window_states, "states in the odometry graph's fixed-lag window (>= 2)");
  v.field("gravity_alignment_s", gravity_alignment_s,
          "s, span of the first scans used to level the world frame with lidar and IMU (0: IMU "
          "attitude only)");
  v.field("gravity_tilt_sigma_deg", gravity_tilt_sigma_deg,
          "deg, prior 1-sigma of the levelled frame's tilt, estimated on (0: held as levelled)");
  v.section("imu", imu, "IMU noise model");
  v.section("health", health,
            "when a scan is degraded or the track lost (docs/odometry.md, Health)");
}

LidarSigmas OdometryConfig::lidarSigmas(double fitness_m2, double inflation) const {
  const double ratio = std::max(1.0, fitness_m2 / fitness_threshold_m2);
  const double growth = std::pow(ratio, fitness_sigma_exponent) * inflation;
  const double heading_rad = lidar_heading_sigma_rad > 0.0 ? lidar_heading_sigma_rad : lidar_sigma;
  return {lidar_sigma * growth, lidar_sigma * growth, heading_rad * growth};
}

double OdometryConfig::coarsestNdtResolutionM() const {
  return std::max(ndt_coarse_resolution_m, ndt_resolution_m);
}

std::vector<double> OdometryConfig::ndtResolutionsM() const {
  if (ndt_coarse_resolution_m > ndt_resolution_m)
    return {ndt_coarse_resolution_m, ndt_resolution_m};
  return {ndt_resolution_m};
}

void OdometryConfig::validate() const {
  requireNonNegative("min_range_m", min_range_m, "m");
  requireInRange("max_range_m", max_range_m, min_range_m + 0.1, 1000.0, "m");
  requireInRange("voxel_size_m", voxel_size_m, 0.01, 5.0, "m");
  requireInRange("ndt_resolution_m", ndt_resolution_m, 0.1, 10.0, "m");
  if (ndt_coarse_resolution_m != 0.0) {
    requireInRange("ndt_coarse_resolution_m", ndt_coarse_resolution_m, ndt_resolution_m, 10.0,
                   "m (0: one pass)");
  }
  requireInRange("local_map_voxel_m", local_map_voxel_m, 0.01, 5.0, "m");
  // A range noise of metres is a unit error (mm written as m), not a lidar.
  requireInRange("lidar_range_sigma_m", lidar_range_sigma_m, 0.0, 0.5, "m");
  requireInRange("lidar_range_sigma_per_m", lidar_range_sigma_per_m, 0.0, 0.05, "");
  requireInRange("local_map_keyframes", local_map_keyframes, 1, 1000, "keyframes");
  requirePositive("lidar_sigma", lidar_sigma, "m");
  requireNonNegative("lidar_heading_sigma_rad", lidar_heading_sigma_rad, "rad");
  requirePositive("fitness_threshold_m2", fitness_threshold_m2, "m^2");
  requireNonNegative("fitness_sigma_exponent", fitness_sigma_exponent, "");
  requirePositive("max_fitness_m2", max_fitness_m2, "m^2");
  requirePositive("max_jump_m", max_jump_m, "m");
  requirePositive("max_jump_deg", max_jump_deg, "deg");
  requireInRange("degenerate_condition", degenerate_condition, 10.0, 1e12, "");
  requirePositive("keyframe_distance_m", keyframe_distance_m, "m");
  requireNonNegative("keyframe_rotation_weight_m_per_rad", keyframe_rotation_weight_m_per_rad,
                     "m/rad");
  requireInRange("window_states", window_states, 2, 50, "states");
  requireInRange("gravity_alignment_s", gravity_alignment_s, 0.0, 30.0, "s");
  requireInRange("gravity_tilt_sigma_deg", gravity_tilt_sigma_deg, 0.0, 10.0, "deg");
}

}  // namespace taiga
