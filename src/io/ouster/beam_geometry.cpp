#include "taiga/io/ouster/beam_geometry.hpp"

#include <cassert>
#include <cmath>
#include <numbers>

#include "taiga/core/angles.hpp"

namespace taiga::io::ouster {
namespace {

constexpr double kMmToM = 1e-3;

}  // namespace

BeamGeometry::BeamGeometry(const SensorInfo& info) {
  const auto columns = static_cast<std::size_t>(info.columns_per_frame);
  cos_encoder_.resize(columns);
  sin_encoder_.resize(columns);
  for (std::size_t c = 0; c < columns; ++c) {
    const double theta_e =
        2.0 * std::numbers::pi * (1.0 - static_cast<double>(c) / static_cast<double>(columns));
    cos_encoder_[c] = std::cos(theta_e);
    sin_encoder_[c] = std::sin(theta_e);
  }
  for (std::size_t row = 0; row < info.beam_altitude_angles_deg.size(); ++row) {
    const double theta_a = -info.beam_azimuth_angles_deg[row] * kRadPerDeg;
    const double phi = info.beam_altitude_angles_deg[row] * kRadPerDeg;
    cos_azimuth_.push_back(std::cos(theta_a));
    sin_azimuth_.push_back(std::sin(theta_a));
    cos_altitude_.push_back(std::cos(phi));
    sin_altitude_.push_back(std::sin(phi));
  }
  const Eigen::Vector3d beam_origin_mm = info.T_lidar_beam.translation() / kMmToM;
  beam_x_mm_ = beam_origin_mm.x();
  beam_z_mm_ = beam_origin_mm.z();
  beam_distance_mm_ = std::hypot(beam_x_mm_, beam_z_mm_);
  R_sensor_lidar_ = info.T_sensor_lidar.rotation().matrix();
  t_sensor_lidar_mm_ = info.T_sensor_lidar.translation() / kMmToM;
}

Eigen::Vector3d BeamGeometry::pointInSensor(int row, int measurement_id,
                                            std::uint32_t range_mm) const {
  assert(row >= 0 && row < rows() && measurement_id >= 0 && measurement_id < columns());
  const auto r = static_cast<std::size_t>(row);
  const auto c = static_cast<std::size_t>(measurement_id);
  // cos/sin(theta_e + theta_a) from the per-column and per-row tables.
  const double cos_sum = cos_encoder_[c] * cos_azimuth_[r] - sin_encoder_[c] * sin_azimuth_[r];
  const double sin_sum = sin_encoder_[c] * cos_azimuth_[r] + cos_encoder_[c] * sin_azimuth_[r];
  const double along_beam_mm = static_cast<double>(range_mm) - beam_distance_mm_;
  const Eigen::Vector3d p_lidar_mm(
      along_beam_mm * cos_sum * cos_altitude_[r] + beam_x_mm_ * cos_encoder_[c],
      along_beam_mm * sin_sum * cos_altitude_[r] + beam_x_mm_ * sin_encoder_[c],
      along_beam_mm * sin_altitude_[r] + beam_z_mm_);
  return (R_sensor_lidar_ * p_lidar_mm + t_sensor_lidar_mm_) * kMmToM;
}

}  // namespace taiga::io::ouster
