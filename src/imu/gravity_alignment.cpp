#include "taiga/imu/gravity_alignment.hpp"

#include <Eigen/Dense>
#include <stdexcept>

namespace taiga::imu {
namespace {

/// The rows' residual scale, m and m/s: what a centimetre-accurate lidar pose leaves. It weighs
/// the bias prior against the rows (the rows themselves are unweighted, as in VINS-Mono).
constexpr double kRowSigma = 0.01;

/// Least-squares system over the unknowns [v_0 .. v_N (3 each); g (3) when free; b_a (3)].
struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
};

LinearSystem buildSystem(std::span<const lie::SE3> poses, std::span<const Preintegrator> increments,
                         const AccelBiasPrior& bias_prior, const Vector3* fixed_gravity) {
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());
  const Eigen::Index gravity_column = 3 * n_poses;
  const Eigen::Index bias_column = gravity_column + (fixed_gravity ? 0 : 3);
  const Eigen::Index rows = 6 * (n_poses - 1) + 3;
  LinearSystem s{Eigen::MatrixXd::Zero(rows, bias_column + 3), Eigen::VectorXd::Zero(rows)};
  for (Eigen::Index k = 0; k + 1 < n_poses; ++k) {
    const Preintegrator& pre = increments[static_cast<std::size_t>(k)];
    const double dt = pre.deltaTime();
    const Matrix3 R_k = poses[k].rotation().matrix();
    // The increments to first order in the bias b about their own b_hat ([Forster] Eq. 44):
    // dp(b) = dp + dP_dba (b - b_hat), likewise dv.
    const Vector3& b_hat = pre.biasHat().accel_mps2;
    const Vector3 dp_world = poses[k + 1].translation() - poses[k].translation() -
                             R_k * (pre.deltaP() - pre.dP_dba() * b_hat);
    const Vector3 dv_world = R_k * (pre.deltaV() - pre.dV_dba() * b_hat);
    const Eigen::Index row = 6 * k;
    // Position rows: v_k dt + 1/2 g dt^2 + R_k dP_dba b = p_{k+1} - p_k - R_k (dp - dP_dba b_hat).
    s.A.block<3, 3>(row, 3 * k) = Matrix3::Identity() * dt;
    s.A.block<3, 3>(row, bias_column) = R_k * pre.dP_dba();
    // Velocity rows: v_{k+1} - v_k - g dt - R_k dV_dba b = R_k (dv - dV_dba b_hat).
    s.A.block<3, 3>(row + 3, 3 * k) = -Matrix3::Identity();
    s.A.block<3, 3>(row + 3, 3 * (k + 1)) = Matrix3::Identity();
    s.A.block<3, 3>(row + 3, bias_column) = -R_k * pre.dV_dba();
    s.b.segment<3>(row) = dp_world;
    s.b.segment<3>(row + 3) = dv_world;
    if (fixed_gravity) {
      s.b.segment<3>(row) -= 0.5 * *fixed_gravity * dt * dt;
      s.b.segment<3>(row + 3) += *fixed_gravity * dt;
    } else {
      s.A.block<3, 3>(row, gravity_column) = 0.5 * Matrix3::Identity() * dt * dt;
      s.A.block<3, 3>(row + 3, gravity_column) = -Matrix3::Identity() * dt;
    }
  }
  // The prior: (b - b_prior) / sigma, scaled to the rows.
  const double weight = kRowSigma / bias_prior.sigma_mps2;
  s.A.block<3, 3>(rows - 3, bias_column) = Matrix3::Identity() * weight;
  s.b.tail<3>() = bias_prior.mean_mps2 * weight;
  return s;
}

}  // namespace

GravityAlignment alignGravity(std::span<const lie::SE3> poses,
                              std::span<const Preintegrator> increments, double gravity_mps2,
                              const AccelBiasPrior& bias_prior) {
  if (poses.size() < 3 || increments.size() + 1 != poses.size())
    throw std::invalid_argument("alignGravity: needs N + 1 >= 3 poses and N increments");
  if (!(bias_prior.sigma_mps2 > 0.0))
    throw std::invalid_argument("alignGravity: the bias prior's sigma must be positive");
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());

  const LinearSystem free = buildSystem(poses, increments, bias_prior, nullptr);
  const Eigen::VectorXd x_free = free.A.colPivHouseholderQr().solve(free.b);
  const Vector3 g_free = x_free.segment<3>(3 * n_poses);

  GravityAlignment result;
  result.estimated_magnitude_mps2 = g_free.norm();
  result.gravity_world = g_free.normalized() * gravity_mps2;
  const LinearSystem fixed = buildSystem(poses, increments, bias_prior, &result.gravity_world);
  const Eigen::VectorXd x = fixed.A.colPivHouseholderQr().solve(fixed.b);
  for (Eigen::Index k = 0; k < n_poses; ++k) result.v_world.push_back(x.segment<3>(3 * k));
  result.accel_bias_mps2 = x.tail<3>();
  result.residual_rms =
      std::sqrt((fixed.A * x - fixed.b).squaredNorm() / static_cast<double>(fixed.b.size()));
  result.R_levelled_world =
      lie::SO3(Eigen::Quaterniond::FromTwoVectors(result.gravity_world, Vector3(0.0, 0.0, -1.0)));
  return result;
}

}  // namespace taiga::imu
