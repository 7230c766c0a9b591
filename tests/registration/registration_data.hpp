#pragma once
// The real scan pair of ../shared/data/registration (two HDL-32E scans, small_gicp's test data)
// and helpers for registration tests: reference transform, random perturbations, errors.

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::test {

inline const std::filesystem::path kRegistrationData = "../shared/data/registration";

inline std::vector<Eigen::Vector3d> loadPositions(const std::filesystem::path& path) {
  return io::readPointCloudFile(path, 0.0).cloud.positions;
}

/// A 4x4 row-major matrix in a text file.
inline lie::SE3 loadTransform(const std::filesystem::path& path) {
  std::ifstream in(path);
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!(in >> T(r, c))) throw std::runtime_error("cannot read " + path.string());
    }
  }
  return lie::SE3::fromMatrix(T);
}

/// Translation error (m) and rotation error (deg) of `estimate` against `reference`.
struct PoseError {
  double translation_m;
  double rotation_deg;
};
inline PoseError poseError(const lie::SE3& estimate, const lie::SE3& reference) {
  const lie::SE3 delta = reference.inverse() * estimate;
  return {delta.translation().norm(), delta.rotation().Log().norm() * kDegPerRad};
}

/// A perturbation with a translation of uniform random length in [0, max_m] along a random
/// direction and a rotation of uniform random angle in [0, max_deg] about a random axis.
inline lie::SE3 randomPerturbation(std::mt19937& rng, double max_m, double max_deg) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Vector3d dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const double t = max_m * uniform(rng);
  const double angle = max_deg * kRadPerDeg * uniform(rng);
  return lie::SE3(lie::SO3::Exp(axis * angle), dir * t);
}

}  // namespace taiga::test
