#include "taiga/imu/gravity_alignment.hpp"

#include <Eigen/Dense>
#include <stdexcept>

namespace taiga::imu {
namespace {

/// Least-squares system over the unknowns [v_0 .. v_N (3 each); g (3) when free].
struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
};

LinearSystem buildSystem(std::span<const lie::SE3> poses, std::span<const Preintegrator> increments,
                         const Vector3* fixed_gravity) {
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());
  const Eigen::Index unknowns = 3 * n_poses + (fixed_gravity ? 0 : 3);
  LinearSystem s{Eigen::MatrixXd::Zero(6 * (n_poses - 1), unknowns),
                 Eigen::VectorXd::Zero(6 * (n_poses - 1))};
  for (Eigen::Index k = 0; k + 1 < n_poses; ++k) {
    const Preintegrator& pre = increments[static_cast<std::size_t>(k)];
    const double dt = pre.deltaTime();
    const Matrix3 R_k = poses[k].rotation().matrix();
    const Vector3 dp_world =
        poses[k + 1].translation() - poses[k].translation() - R_k * pre.deltaP();
    const Vector3 dv_world = R_k * pre.deltaV();
    const Eigen::Index row = 6 * k;
    // Position rows: v_k dt + 1/2 g dt^2 = p_{k+1} - p_k - R_k dp.
    s.A.block<3, 3>(row, 3 * k) = Matrix3::Identity() * dt;
    // Velocity rows: v_{k+1} - v_k - g dt = R_k dv.
    s.A.block<3, 3>(row + 3, 3 * k) = -Matrix3::Identity();
    s.A.block<3, 3>(row + 3, 3 * (k + 1)) = Matrix3::Identity();
    s.b.segment<3>(row) = dp_world;
    s.b.segment<3>(row + 3) = dv_world;
    if (fixed_gravity) {
      s.b.segment<3>(row) -= 0.5 * *fixed_gravity * dt * dt;
      s.b.segment<3>(row + 3) += *fixed_gravity * dt;
    } else {
      s.A.block<3, 3>(row, 3 * n_poses) = 0.5 * Matrix3::Identity() * dt * dt;
      s.A.block<3, 3>(row + 3, 3 * n_poses) = -Matrix3::Identity() * dt;
    }
  }
  return s;
}

}  // namespace

GravityAlignment alignGravity(std::span<const lie::SE3> poses,
                              std::span<const Preintegrator> increments, double gravity_mps2) {
  if (poses.size() < 3 || increments.size() + 1 != poses.size())
    throw std::invalid_argument("alignGravity: needs N + 1 >= 3 poses and N increments");
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());

  const LinearSystem free = buildSystem(poses, increments, nullptr);
  const Eigen::VectorXd x_free = free.A.colPivHouseholderQr().solve(free.b);
  const Vector3 g_free = x_free.tail<3>();

  GravityAlignment result;
  result.estimated_magnitude_mps2 = g_free.norm();
  result.gravity_world = g_free.normalized() * gravity_mps2;
  const LinearSystem fixed = buildSystem(poses, increments, &result.gravity_world);
  const Eigen::VectorXd v = fixed.A.colPivHouseholderQr().solve(fixed.b);
  for (Eigen::Index k = 0; k < n_poses; ++k) result.v_world.push_back(v.segment<3>(3 * k));
  result.residual_rms =
      std::sqrt((fixed.A * v - fixed.b).squaredNorm() / static_cast<double>(fixed.b.size()));
  result.R_levelled_world =
      lie::SO3(Eigen::Quaterniond::FromTwoVectors(result.gravity_world, Vector3(0.0, 0.0, -1.0)));
  return result;
}

}  // namespace taiga::imu
