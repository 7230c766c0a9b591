#pragma once
// Range to XYZ for Ouster sensors, as the Ouster firmware user manual defines it ("Coordinate
// Frames and XYZ Calculation", "Lidar Range to XYZ") and the Ouster SDK's XYZ lookup table
// computes it:
//
//   theta_e = 2 pi (1 - measurement_id / columns_per_frame)      encoder angle of the column
//   theta_a = -2 pi beam_azimuth_angles[row] / 360                beam azimuth offset
//   phi     =  2 pi beam_altitude_angles[row] / 360               beam altitude
//   d       = (cos(theta_e + theta_a) cos(phi), sin(theta_e + theta_a) cos(phi), sin(phi))
//   (bx, bz)= beam origin in the lidar frame (beam_to_lidar_transform translation; bx =
//             lidar_origin_to_beam_origin_mm and bz = 0 before firmware 2.5), n = |(bx, bz)|
//   p_lidar = (r - n) d + (bx cos(theta_e), bx sin(theta_e), bz)      [mm]
//   p_sensor = lidar_to_sensor_transform * p_lidar, then mm -> m.
//
// The result is in the Ouster SENSOR frame (x forward, away from the connector; z up), the frame
// of the Ouster SDK's XYZ points and of ouster-ros point clouds. Zero range means no return.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "taiga/io/ouster/sensor_info.hpp"

namespace taiga::io::ouster {

class BeamGeometry {
 public:
  explicit BeamGeometry(const SensorInfo& info);

  /// The point measured by beam `row` in column `measurement_id` at `range_mm`, in the sensor
  /// frame, m. Requires row < pixels_per_column and measurement_id < columns_per_frame.
  Eigen::Vector3d pointInSensor(int row, int measurement_id, std::uint32_t range_mm) const;

  int rows() const { return static_cast<int>(cos_altitude_.size()); }
  int columns() const { return static_cast<int>(cos_encoder_.size()); }

 private:
  // Per column (encoder angle) and per row (beam angles) tables; their products give d.
  std::vector<double> cos_encoder_, sin_encoder_;
  std::vector<double> cos_azimuth_, sin_azimuth_, cos_altitude_, sin_altitude_;
  double beam_x_mm_ = 0.0, beam_z_mm_ = 0.0, beam_distance_mm_ = 0.0;
  Eigen::Matrix3d R_sensor_lidar_;
  Eigen::Vector3d t_sensor_lidar_mm_;
};

}  // namespace taiga::io::ouster
