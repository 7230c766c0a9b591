#pragma once
// One entry point for all methods: register SOURCE points to TARGET points from a guess, and fill
// in the thesis fitness score. For repeated registrations against one map, build the target
// (NdtTarget, GicpCloud) once and call the method's align function instead.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>

#include "taiga/core/odometry_config.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::registration {

enum class Method { kNdt, kD2dNdt, kGicp };

/// "ndt", "d2d", "gicp" (the command-line names).
std::optional<Method> methodFromName(const std::string& name);
std::string methodName(Method method);

struct RegistrationConfig {
  Method method = Method::kNdt;
  NdtConfig ndt;
  GicpConfig gicp;
  bool compute_fitness = true;  ///< builds a kd-tree over the target for the fitness score
};

/// The registration of the odometry's configuration (odometry.method, the NDT passes of
/// OdometryConfig::ndtResolutionsM() coarse to fine, odometry.ndt_neighbours): built here once and
/// shared by the odometry, its initialization and loop closure, which adapt it where their
/// problem differs.
RegistrationConfig registrationConfigFor(const OdometryConfig& odometry);

RegistrationResult registerClouds(std::span<const Eigen::Vector3d> source,
                                  std::span<const Eigen::Vector3d> target,
                                  const lie::SE3& guess_T_target_source,
                                  const RegistrationConfig& config);

}  // namespace taiga::registration
