#include "taiga/registration/registration.hpp"

#include "taiga/registration/kdtree.hpp"

namespace taiga::registration {

std::optional<Method> methodFromName(const std::string& name) {
  if (name == "ndt") return Method::kNdt;
  if (name == "d2d") return Method::kD2dNdt;
  if (name == "gicp") return Method::kGicp;
  return std::nullopt;
}

std::string methodName(Method method) {
  switch (method) {
    case Method::kNdt:
      return "ndt";
    case Method::kD2dNdt:
      return "d2d";
    case Method::kGicp:
      return "gicp";
  }
  return "?";
}

RegistrationConfig registrationConfigFor(const OdometryConfig& odometry) {
  RegistrationConfig config;
  // OdometryConfig::validate() admits only the names methodFromName knows.
  config.method = methodFromName(odometry.method).value_or(Method::kNdt);
  const std::vector<double> resolutions_m = odometry.ndtResolutionsM();
  config.ndt.resolution_m = resolutions_m.back();
  config.ndt.coarse_resolutions_m.assign(resolutions_m.begin(), resolutions_m.end() - 1);
  config.ndt.search =
      odometry.ndt_neighbours == "direct1" ? NeighbourSearch::kDirect1 : NeighbourSearch::kDirect7;
  config.ndt.stem_cells = odometry.ndt_stem_cells;
  config.ndt.stem_cells_across_borders = odometry.ndt_stem_cells_across_borders;
  if (odometry.ndt_stem_cells_range_noise) {
    config.ndt.range_sigma_m = odometry.lidar_range_sigma_m;
    config.ndt.range_sigma_per_m = odometry.lidar_range_sigma_per_m;
  }
  return config;
}

RegistrationResult registerClouds(std::span<const Eigen::Vector3d> source,
                                  std::span<const Eigen::Vector3d> target, const lie::SE3& guess,
                                  const RegistrationConfig& config) {
  RegistrationResult result;
  switch (config.method) {
    case Method::kNdt:
      result = alignNdt(source, target, guess, config.ndt);
      break;
    case Method::kD2dNdt:
      result = alignD2dNdt(source, target, guess, config.ndt);
      break;
    case Method::kGicp:
      result = alignGicp(source, target, guess, config.gicp);
      break;
  }
  if (config.compute_fitness && !source.empty() && !target.empty()) {
    result.fitness_m2 = fitnessScore(source, KdTree(target), result.T_target_source);
  }
  return result;
}

}  // namespace taiga::registration
