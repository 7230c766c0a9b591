#include "taiga/sim/sensor_models.hpp"

#include <fmt/format.h>

#include <numbers>
#include <vector>

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

/// A Velodyne-like head: beams fired from one column, no beam-origin offset, the points in the
/// sensor frame; no IMU of its own, so the rig's IMU is taken 10 cm below the sensor, unrotated
/// (a typical mount of an external IMU module).
LidarGeometry velodyne(std::vector<double> altitudes_deg, const char* name) {
  LidarGeometry g;
  g.beam_altitude_deg = std::move(altitudes_deg);
  g.beam_azimuth_deg.assign(g.beam_altitude_deg.size(), 0.0);
  g.T_sensor_imu = lie::SE3(lie::SO3(), Eigen::Vector3d(0.0, 0.0, -0.10));
  g.source = fmt::format("built-in {}", name);
  return g;
}

/// Velodyne VLP-16 (datasheet): 16 beams from +15 to -15 deg, 2 deg apart (rows top to bottom
/// as the other models; the driver's ring numbers differ). At 10 Hz it fires 1800 times per
/// rotation: `lidar: {model: vlp-16, columns: 1800}`.
LidarGeometry vlp16() {
  std::vector<double> a;
  for (int i = 0; i < 16; ++i) a.push_back(15.0 - 2.0 * i);
  return velodyne(std::move(a), "vlp-16");
}

/// Velodyne HDL-32E (datasheet): 32 beams from +10.67 to -30.67 deg, 1.33 deg apart; about 2170
/// firings per rotation at 10 Hz (`columns: 2048` is close).
LidarGeometry hdl32e() {
  std::vector<double> a;
  for (int i = 0; i < 32; ++i) a.push_back(10.67 - (10.67 + 30.67) * i / 31.0);
  return velodyne(std::move(a), "hdl-32e");
}

struct Model {
  const char* name;
  LidarGeometry (*make)();
};
constexpr Model kModels[] = {{"os0-128", os0_128}, {"vlp-16", vlp16}, {"hdl-32e", hdl32e}};

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
