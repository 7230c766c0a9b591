#pragma once
// Configuration of the lidar-inertial odometry (pipeline/): preprocessing, registration to the
// local map, the lidar factor's covariance, keyframes and the IMU noise model.

#include <string>
#include <vector>

#include "taiga/core/config.hpp"
#include "taiga/core/imu_noise.hpp"

namespace taiga {

/// The `odometry.imu` section: the noise model (used as it is by the preintegration) and the
/// local gravity magnitude.
struct ImuNoiseConfig final : ConfigSection, ImuNoise {
  double gravity_mps2 = 9.81;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

/// The `odometry.health` section: when a scan is `degraded` or the track `lost`
/// (pipeline/health_monitor.hpp, docs/odometry.md "Health").
struct HealthConfig final : ConfigSection {
  /// The track is lost after this long without a scan judged ok (dead reckoning only), s.
  double lost_after_s = 1.0;
  /// ... and after at least this many scans in a row not ok (1 s is 2 scans at 2 Hz).
  int lost_after_scans = 3;
  /// Lost for this long more, the odometry gives up the old local map and starts a new one from
  /// the next scan (a new map segment), s.
  double reinitialize_after_s = 2.0;
  /// Scans judged ok in a row that end a lost stretch.
  int recovery_scans = 3;
  /// Recent ok scans whose median fitness and inlier share are the yardstick.
  int history_scans = 10;
  /// A fitness above this many times the recent median is degraded.
  double fitness_ratio = 4.0;
  /// Fitness below this is never judged against the median, m^2 (noise-level values).
  double fitness_floor_m2 = 0.02;
  /// An inlier share below this fraction of the recent median is degraded.
  double inlier_share_ratio = 0.6;
  /// Speeds above this are impossible for the rig: the track is lost, m/s.
  double max_speed_mps = 30.0;
  /// A change of velocity between consecutive states faster than this is degraded, m/s^2.
  double max_acceleration_mps2 = 30.0;
  /// Bias estimates beyond these are implausible for a working MEMS IMU: degraded.
  double max_accel_bias_mps2 = 1.5;
  double max_gyro_bias_dps = 10.0;
  /// With an IMU: a median rotation between the IMU's prediction and the registration above this
  /// over the run means the rig's calibration or noise settings are suspect, deg per scan.
  double max_median_innovation_deg = 0.5;
  /// With an IMU: a stretch without IMU readings longer than this before a scan degrades it, and
  /// the IMU factor over it is weakened to what the readings around it can tell, s.
  double max_imu_gap_s = 0.05;
  /// Scans with fewer points after the voxel filter than this fraction of the run's median are
  /// reported as sparse (lost packets, a blocked view): a run-level note, not a scan status.
  double sparse_scan_ratio = 0.4;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

/// Sigmas of a registration-based pose measurement (thesis Eq. 36, see OdometryConfig::
/// lidarSigmas()).
struct LidarSigmas {
  double translation_m = 0.0;
  double tilt_rad = 0.0;     ///< roll and pitch
  double heading_rad = 0.0;  ///< about the vertical
};

struct OdometryConfig final : ConfigSection {
  // Preprocessing (thesis 3.1.1).
  double min_range_m = 1.0;  ///< returns closer than this (the operator, the rig) are dropped
  double max_range_m = 80.0;
  double voxel_size_m = 0.4;  ///< voxel filter of the registration source
  /// Which point stands for each of its voxels: centroid, or measured (the return nearest the
  /// voxel's mean: less shrink, but a lidar-only re-attachment failed with it;
  /// docs/registration.md, "Bias").
  std::string voxel_point = "centroid";
  // Registration to the local map.
  /// auto | lidar_inertial | lidar_only. auto: lidar-only when the recording has delivered no
  /// IMU reading within its first 2 s of scans.
  std::string imu_use = "auto";
  std::string method = "ndt";  ///< ndt | d2d | gicp
  /// NDT cell edge. The thesis' 1 m suits any lidar; with 64 beams or more 0.5 m shrinks the
  /// odometry's steps less (docs/odometry.md, "Scale"; config/os0-128-*.yaml set it).
  double ndt_resolution_m = 1.0;
  /// Without an IMU, for the first two scans and in loop closure: a first pass at this coarser
  /// cell edge, for its wider basin; 0 or not coarser than ndt_resolution_m: none.
  double ndt_coarse_resolution_m = 1.0;
  std::string ndt_neighbours = "direct1";  ///< direct1 | direct7: NDT cells scored per point
  /// NDT cells holding a stem's section score points by their distance to its circle
  /// (registration/ndt.hpp, "Stem cells"; docs/registration.md, "Bias"): half the shrink.
  bool ndt_stem_cells = true;
  /// ...also where a stem is cut by cell borders (NdtConfig::stem_cells_across_borders). Off: it
  /// took at most 0.003 % more off the shrink, and IMU-gap bridging diverged with it
  /// (docs/registration.md, "Local-map points on the surface, and stems across cell borders").
  bool ndt_stem_cells_across_borders = false;
  /// The stem cells' circles fitted with the local map's range noise taken out (errors in
  /// variables along each point's beam; docs/registration.md, "Range noise in the stem cells"):
  /// the lidar's range noise, 1-sigma, lidar_range_sigma_m + lidar_range_sigma_per_m x range.
  /// The defaults are an OS0's; a noise stated twice too large costs more than none.
  bool ndt_stem_cells_range_noise = true;
  double lidar_range_sigma_m = 0.01;
  double lidar_range_sigma_per_m = 0.0005;
  double local_map_voxel_m = 0.2;          ///< keyframe points enter the local map at this spacing
  /// Which point stands for each local-map voxel of a keyframe: centroid, or bearing (the return
  /// whose direction from the lidar is nearest the centroid's: on the surface, with its range
  /// noise not selected for; docs/registration.md, "Local-map points on the surface").
  std::string local_map_point = "bearing";
  int local_map_keyframes = 20;            ///< keyframes the local map holds
  // Lidar factor covariance from the fitness score (thesis Eq. 36, see docs/odometry.md).
  double lidar_sigma =
      0.01;  ///< sigma_sm: m and rad (roll, pitch; heading unless set below), at good fitness
  double lidar_heading_sigma_rad = 0.001;  ///< heading sigma at good fitness; 0: lidar_sigma
  double fitness_threshold_m2 = 0.3;       ///< tau_fs
  double fitness_sigma_exponent = 2.0;     ///< theta_smsc
  // Rejection of registrations that disagree with the IMU prediction or did not work.
  double max_fitness_m2 = 2.0;
  double max_jump_m = 0.5;
  double max_jump_deg = 5.0;
  double degenerate_condition =
      1e5;  ///< Hessian condition number above which the factor is inflated
  // Keyframes (thesis Eq. 37: travelled distance weighted with rotation).
  double keyframe_distance_m = 1.0;
  double keyframe_rotation_weight_m_per_rad = 2.0;
  // Odometry graph.
  int window_states = 5;
  /// Span of the first scans whose lidar poses and IMU increments level the world frame (gravity
  /// alignment, imu/gravity_alignment.hpp), s; 0 keeps the attitude from the IMU alone.
  double gravity_alignment_s = 2.0;
  /// Prior 1-sigma of the levelled frame's tilt, deg, which the odometry then keeps estimating
  /// (backend/odometry_smoother.hpp); 0 holds the frame as levelled.
  double gravity_tilt_sigma_deg = 1.0;
  ImuNoiseConfig imu;
  HealthConfig health;

  /// Thesis Eq. 36 as docs/odometry.md reads it: sigma_sm while the fitness is at most tau_fs,
  /// times (fitness / tau_fs)^theta_smsc above it, times `inflation`; heading with its own sigma.
  LidarSigmas lidarSigmas(double fitness_m2, double inflation = 1.0) const;

  /// The NDT passes' cell edges, coarse to fine: {ndt_coarse_resolution_m, ndt_resolution_m},
  /// or {ndt_resolution_m} alone when the coarse one is 0 or not coarser.
  std::vector<double> ndtResolutionsM() const;
  /// The coarsest of them.
  double coarsestNdtResolutionM() const;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
