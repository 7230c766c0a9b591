#include "taiga/georef/fit.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "taiga/core/errors.hpp"

namespace taiga::georef {

std::string_view methodName(GeorefMethod method) {
  switch (method) {
    case GeorefMethod::kClosed:
      return "closed";
    case GeorefMethod::kPf3:
      return "pf3";
    case GeorefMethod::kPf6:
      return "pf6";
    case GeorefMethod::kRobust:
      return "robust";
  }
  return "robust";
}

GeorefMethod parseMethod(std::string_view name) {
  for (const GeorefMethod m :
       {GeorefMethod::kClosed, GeorefMethod::kPf3, GeorefMethod::kPf6, GeorefMethod::kRobust})
    if (methodName(m) == name) return m;
  throw InputError(fmt::format("georef method '{}' is not one of closed, pf3, pf6, robust", name));
}

void FitOptions::validate() const {
  const auto positive = [](double value, const char* field) {
    if (!(std::isfinite(value) && value > 0.0))
      throw std::invalid_argument(fmt::format("georef fit: {} must be positive, got {}", field, value));
  };
  positive(trajectory_position_sigma_m, "trajectory_position_sigma_m");
  positive(trajectory_rotation_sigma_rad, "trajectory_rotation_sigma_rad");
  positive(orientation_tilt_sigma_rad, "orientation_tilt_sigma_rad");
  positive(orientation_heading_sigma_rad, "orientation_heading_sigma_rad");
  positive(gravity_tilt_sigma_rad, "gravity_tilt_sigma_rad");
  positive(cauchy_scale, "cauchy_scale");
  positive(huber_threshold, "huber_threshold");
  positive(outlier_threshold, "outlier_threshold");
  positive(convergence_step, "convergence_step");
  if (!(std::isfinite(error_correlation_time_s) && error_correlation_time_s >= 0.0))
    throw std::invalid_argument(fmt::format(
        "georef fit: error_correlation_time_s must be >= 0, got {}", error_correlation_time_s));
  if (max_iterations < 1) throw std::invalid_argument("georef fit: max_iterations must be >= 1");
}

Eigen::Vector3d rollPitchYaw(const lie::SO3& rotation) {
  const Eigen::Matrix3d R = rotation.matrix();
  // R = Rz(yaw) Ry(pitch) Rx(roll): R(2,0) = -sin(pitch), R(2,1)/R(2,2) = tan(roll),
  // R(1,0)/R(0,0) = tan(yaw) (SO3::yaw()).
  return {std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)), rotation.yaw()};
}

}  // namespace taiga::georef
