#include "taiga/core/rig_config.hpp"

#include <fmt/format.h>

#include <array>

namespace taiga {
namespace {
constexpr std::array<std::string_view, 3> kAxes{"x", "y", "z"};  // GyroAxes' rows
}  // namespace

void GyroAxes::visit(ConfigVisitor& v) {
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d row = M_reading_true.row(i).transpose();
    v.field(kAxes[i], row,
            "the gyro's reading on this axis per rad/s about the IMU frame's x, y and z");
    M_reading_true.row(i) = row.transpose();
  }
}

void GyroAxes::validate() const {
  // Beyond 20 % the matrix is not a MEMS gyro's error but a wrong unit or a swapped axis, which
  // belongs in T_body_imu.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      requireInRange(fmt::format("{}[{}]", kAxes[r], c), M_reading_true(r, c),
                     (r == c ? 1.0 : 0.0) - 0.2, (r == c ? 1.0 : 0.0) + 0.2,
                     "(a scale or axis error beyond 20 % is a unit or axis mistake)");
}

void RigConfig::visit(ConfigVisitor& v) {
  v.field("T_body_lidar", T_body_lidar,
          "pose of the lidar frame in the body frame, p_body = T_body_lidar * p_lidar");
  v.field("T_body_imu", T_body_imu,
          "pose of the IMU frame in the body frame, p_body = T_body_imu * p_imu");
  v.field("lidar_time_offset_s", lidar_time_offset_s,
          "s, added to lidar times to put them on the IMU clock");
  static constexpr std::array<std::pair<std::string_view, AccelerationUnit>, 3> kUnits{{
      {"auto", AccelerationUnit::kAuto},
      {"mps2", AccelerationUnit::kMetersPerSecond2},
      {"g", AccelerationUnit::kStandardGravity},
  }};
  enumField(v, "imu_acceleration_unit", imu_acceleration_unit, kUnits,
            "unit of the IMU acceleration: m/s^2 (mps2), standard gravity (g) or auto-detect");
  v.field("self_boxes_body", self_boxes_body,
          "boxes {min_m, max_m} in the body frame around the rig itself (operator, cabin); "
          "returns inside are dropped");
  v.section("gyro_axes", gyro_axes,
            "the gyro's scale and axis errors, rows x, y, z: reading = rows * true rate "
            "(from a lab calibration, e.g. Kalibr's scale-misalignment model; identity: none)");
}

void RigConfig::validate() const {
  // A clock offset beyond a second is a unit mistake (ms or ns given as s), not a latency.
  requireInRange("lidar_time_offset_s", lidar_time_offset_s, -1.0, 1.0, "s");
  // A lever arm of tens of metres is a unit mistake (mm or cm given as m).
  for (const auto& [key, T] :
       {std::pair{"T_body_lidar", &T_body_lidar}, {"T_body_imu", &T_body_imu}}) {
    requireInRange(std::string(key) + ".translation_m", T->translation().norm(), 0.0, 10.0,
                   "m (length)");
  }
}

}  // namespace taiga
