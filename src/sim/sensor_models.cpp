#include "taiga/sim/sensor_models.hpp"

#include <fmt/format.h>

#include <numbers>

#include "taiga/core/errors.hpp"

namespace taiga::sim {
namespace {

/// Ouster OS0-128 (rev 7 datasheet: 128 channels spread uniformly over a 90 deg vertical field of
/// view, +45 to -45 deg). Its beams fire from four staggered columns; the nominal azimuth offsets
/// (about +-9.15 and +-3.05 deg, beam i in column i mod 4) are those every OS0-128 metadata file
/// shows to within a few hundredths of a degree. Frames from the firmware manual ("Coordinate
/// Frames"): the lidar frame turned 180 deg about z and 36.18 mm above the sensor frame's origin,
/// the beam origin 27.67 mm from the lidar axis, the IMU at (6.253, -11.775, 7.645) mm.
LidarGeometry os0_128() {
  constexpr int kBeams = 128;
  constexpr double kStagger_deg[4] = {9.15, 3.05, -3.05, -9.15};
  LidarGeometry g;
  for (int i = 0; i < kBeams; ++i) {
    g.beam_altitude_deg.push_back(45.0 - 90.0 * i / (kBeams - 1));
    g.beam_azimuth_deg.push_back(kStagger_deg[i % 4]);
  }
  g.lidar_origin_to_beam_origin_m = 0.02767;
  g.T_sensor_lidar = lie::SE3(lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), std::numbers::pi),
                              Eigen::Vector3d(0, 0, 0.03618));
  g.T_sensor_imu = lie::SE3(lie::SO3(), Eigen::Vector3d(0.006253, -0.011775, 0.007645));
  g.source = "built-in os0-128";
  return g;
}

struct Model {
  const char* name;
  LidarGeometry (*make)();
};
constexpr Model kModels[] = {{"os0-128", os0_128}};

}  // namespace

std::vector<std::string> sensorModelNames() {
  std::vector<std::string> names;
  for (const Model& m : kModels) names.emplace_back(m.name);
  return names;
}

LidarGeometry sensorModel(const std::string& name) {
  for (const Model& m : kModels)
    if (name == m.name) return m.make();
  throw InputError(fmt::format("lidar.model: unknown sensor model '{}'; built-in models: {}", name,
                               fmt::join(sensorModelNames(), ", ")));
}

}  // namespace taiga::sim
