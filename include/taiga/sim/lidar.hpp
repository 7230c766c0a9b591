#pragma once
// A spinning lidar in the manner of an Ouster OS0-128 (Ouster firmware user manual, "Coordinate
// Frames and XYZ Calculation"): column j of W fires at t_start + j * period / W from the encoder
// angle theta_e = 2 pi (1 - j / W); beam i leaves the beam origin n (cos theta_e, sin theta_e, 0)
// + (0, 0, z_beam) in direction (cos(theta_e + theta_a) cos phi, sin(theta_e + theta_a) cos phi,
// sin phi) with theta_a = -beam_azimuth_i and phi = beam_altitude_i. Every column is cast from the
// true pose at its own firing time, so scans are skewed by the motion exactly as a real sensor's.
//
// Points are published in the Ouster *sensor* frame (as the Ouster ROS driver does), i.e. the
// lidar frame of taiga's rig is the Ouster sensor frame: p_sensor = T_sensor_lidar * p_lidar.
//
// Modelled: beam divergence with sub-rays (mixed returns at edges: a partly hit stem pulls the
// range of its background, or is returned alone when nothing is behind it), range noise growing
// with range (and, with realism, with weakness of the return), maximum range from reflectivity
// and incidence, random dropouts, lost packets of 16 columns, surfaces swaying in the wind
// (wind.hpp), calibrated reflectivity as intensity. Not modelled: multiple returns, range-dependent intensity,
// blooming from retro-reflectors, the operator's own body occluding the view.

#include <cstdint>
#include <string>
#include <vector>

#include "taiga/io/recording.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/sim/motion.hpp"
#include "taiga/sim/scenario.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

/// Beam geometry and frames of the simulated head.
struct LidarGeometry {
  std::vector<double> beam_altitude_deg;  ///< one per row, + up
  std::vector<double> beam_azimuth_deg;   ///< one per row, offset from the column angle
  double lidar_origin_to_beam_origin_m = 0.0;
  double beam_origin_z_m = 0.0;
  lie::SE3 T_sensor_lidar;  ///< Ouster lidar frame in the Ouster sensor frame
  lie::SE3 T_sensor_imu;    ///< the IMU (= body frame) in the Ouster sensor frame
  std::string source;       ///< the metadata file, or "built-in <model>"
};

/// The built-in model params.model (sensor_models.hpp), or the Ouster metadata file
/// params.metadata_json when one is named, with its rows evenly subsampled to params.beams.
/// InputError for an unknown model or a file that is missing or cannot be read.
LidarGeometry loadLidarGeometry(const LidarParams& params);

class LidarSimulator {
 public:
  LidarSimulator(LidarParams params, LidarGeometry geometry, std::uint64_t seed);

  /// Pose of the published frame (Ouster sensor) in the body frame: the rig's T_body_lidar.
  lie::SE3 T_body_lidar() const { return geometry_.T_sensor_imu.inverse(); }
  double scanPeriod_s() const { return 1.0 / params_.rotation_hz; }
  int rows() const { return static_cast<int>(geometry_.beam_altitude_deg.size()); }
  int columns() const { return params_.columns; }
  const LidarGeometry& geometry() const { return geometry_; }

  /// Scan number `index`, whose first column fires at motion time `t_start_s`. Per-point times
  /// are motion time + `time_offset_s`. Deterministic whatever the number of threads.
  io::Scan simulateScan(const Scene& scene, const WalkingMotion& motion, std::uint64_t index,
                        double t_start_s, double time_offset_s = 0.0) const;

 private:
  LidarParams params_;
  LidarGeometry geometry_;
  std::uint64_t seed_;
  /// Unit direction of every beam in the lidar frame, column-major (column * rows + row).
  std::vector<Eigen::Vector3d> directions_lidar_;
};

}  // namespace taiga::sim
