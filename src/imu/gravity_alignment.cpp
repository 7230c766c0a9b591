#include "taiga/imu/gravity_alignment.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace taiga::imu {
namespace {

/// Least-squares system over the unknowns, in column order: v_0 .. v_N (3 each); then either g
/// (3, free), nothing (g fixed), or a step of g's direction in its tangent plane (2); then the
/// accelerometer bias (3) when it is estimated, with its prior as the last three rows.
struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
};

/// How the gravity and the bias enter one system.
struct Unknowns {
  const Vector3* fixed_gravity = nullptr;  ///< null: g is free
  bool gravity_step = false;               ///< with fixed_gravity: a 2-D step of its direction
  bool zero_accel_bias = false;            ///< increments at b_a = 0 rather than their own
  double bias_prior_weight = 0.0;          ///< > 0: b_a estimated (needs zero_accel_bias)
};

/// Two unit vectors spanning the plane orthogonal to g.
Eigen::Matrix<double, 3, 2> tangentBasis(const Vector3& g) {
  const Vector3 n = g.normalized();
  const Vector3 t1 = n.unitOrthogonal();
  Eigen::Matrix<double, 3, 2> basis;
  basis << t1, n.cross(t1);
  return basis;
}

LinearSystem buildSystem(std::span<const lie::SE3> poses, std::span<const Preintegrator> increments,
                         const Unknowns& u) {
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());
  const Eigen::Index gravity_cols = !u.fixed_gravity ? 3 : (u.gravity_step ? 2 : 0);
  const bool with_bias = u.bias_prior_weight > 0.0;
  const Eigen::Index bias_col = 3 * n_poses + gravity_cols;
  const Eigen::Index data_rows = 6 * (n_poses - 1);
  LinearSystem s{
      Eigen::MatrixXd::Zero(data_rows + (with_bias ? 3 : 0), bias_col + (with_bias ? 3 : 0)),
      Eigen::VectorXd::Zero(data_rows + (with_bias ? 3 : 0))};
  const Eigen::Matrix<double, 3, 2> tangent =
      u.gravity_step ? tangentBasis(*u.fixed_gravity) : Eigen::Matrix<double, 3, 2>::Zero();
  for (Eigen::Index k = 0; k + 1 < n_poses; ++k) {
    const Preintegrator& pre = increments[static_cast<std::size_t>(k)];
    const double dt = pre.deltaTime();
    const Matrix3 R_k = poses[k].rotation().matrix();
    // Increments at a zero accelerometer bias: exact, as b_a enters them linearly (Eq. 44).
    ImuBias at = pre.biasHat();
    if (u.zero_accel_bias) at.accel_mps2.setZero();
    const Vector3 dp = pre.correctedDeltaP(at), dv = pre.correctedDeltaV(at);
    const Eigen::Index row = 6 * k;
    // Position rows: v_k dt + 1/2 g dt^2 + R_k dP/dba b_a = p_{k+1} - p_k - R_k dp.
    s.A.block<3, 3>(row, 3 * k) = Matrix3::Identity() * dt;
    s.b.segment<3>(row) = poses[k + 1].translation() - poses[k].translation() - R_k * dp;
    // Velocity rows: v_{k+1} - v_k - g dt - R_k dV/dba b_a = R_k dv.
    s.A.block<3, 3>(row + 3, 3 * k) = -Matrix3::Identity();
    s.A.block<3, 3>(row + 3, 3 * (k + 1)) = Matrix3::Identity();
    s.b.segment<3>(row + 3) = R_k * dv;
    if (!u.fixed_gravity) {
      s.A.block<3, 3>(row, 3 * n_poses) = 0.5 * Matrix3::Identity() * dt * dt;
      s.A.block<3, 3>(row + 3, 3 * n_poses) = -Matrix3::Identity() * dt;
    } else {
      s.b.segment<3>(row) -= 0.5 * *u.fixed_gravity * dt * dt;
      s.b.segment<3>(row + 3) += *u.fixed_gravity * dt;
      if (u.gravity_step) {
        s.A.block<3, 2>(row, 3 * n_poses) = 0.5 * dt * dt * tangent;
        s.A.block<3, 2>(row + 3, 3 * n_poses) = -dt * tangent;
      }
    }
    if (with_bias) {
      s.A.block<3, 3>(row, bias_col) = R_k * pre.dP_dba();
      s.A.block<3, 3>(row + 3, bias_col) = -R_k * pre.dV_dba();
    }
  }
  if (with_bias) s.A.block<3, 3>(data_rows, bias_col) = Matrix3::Identity() * u.bias_prior_weight;
  return s;
}

double dataResidualRms(const LinearSystem& s, const Eigen::VectorXd& x, Eigen::Index data_rows) {
  return std::sqrt((s.A * x - s.b).head(data_rows).squaredNorm() / static_cast<double>(data_rows));
}

}  // namespace

GravityAlignment alignGravity(std::span<const lie::SE3> poses,
                              std::span<const Preintegrator> increments, double gravity_mps2,
                              double accel_bias_sigma_mps2) {
  if (poses.size() < 3 || increments.size() + 1 != poses.size())
    throw std::invalid_argument("alignGravity: needs N + 1 >= 3 poses and N increments");
  const Eigen::Index n_poses = static_cast<Eigen::Index>(poses.size());
  const Eigen::Index data_rows = 6 * (n_poses - 1);
  const bool with_bias = accel_bias_sigma_mps2 > 0.0;
  // The rows are unweighted, in m and m/s; taken as 1 cm and 1 cm/s, the bias prior's row
  // weighs that over its sigma (measured registrations are better: the prior counts for more).
  constexpr double kRowSigma = 0.01;
  const double bias_prior_weight = with_bias ? kRowSigma / accel_bias_sigma_mps2 : 0.0;

  // Free gravity first (the bias, if estimated, at zero): its direction starts the refinement,
  // its magnitude checks the data.
  const LinearSystem free = buildSystem(poses, increments, {.zero_accel_bias = with_bias});
  const Vector3 g_free = free.A.colPivHouseholderQr().solve(free.b).tail<3>();
  GravityAlignment result;
  result.estimated_magnitude_mps2 = g_free.norm();
  result.gravity_world = g_free.normalized() * gravity_mps2;

  Eigen::VectorXd x;
  if (with_bias) {
    // A tilt and a horizontal accelerometer bias look alike until the rig turns: |g| fixed, its
    // direction refined in the tangent plane together with the bias (VINS-Mono's gravity
    // refinement, Sec. V-B3, with the bias as a further unknown under its prior).
    for (int iteration = 0; iteration < 4; ++iteration) {
      const LinearSystem step = buildSystem(poses, increments,
                                            {.fixed_gravity = &result.gravity_world,
                                             .gravity_step = true,
                                             .zero_accel_bias = true,
                                             .bias_prior_weight = bias_prior_weight});
      x = step.A.colPivHouseholderQr().solve(step.b);
      const Vector3 g_step = tangentBasis(result.gravity_world) * x.segment<2>(3 * n_poses);
      result.gravity_world = (result.gravity_world + g_step).normalized() * gravity_mps2;
    }
  }
  // The velocities (and the bias) for the final gravity.
  const LinearSystem fixed = buildSystem(poses, increments,
                                         {.fixed_gravity = &result.gravity_world,
                                          .zero_accel_bias = with_bias,
                                          .bias_prior_weight = bias_prior_weight});
  x = fixed.A.colPivHouseholderQr().solve(fixed.b);
  for (Eigen::Index k = 0; k < n_poses; ++k) result.v_world.push_back(x.segment<3>(3 * k));
  if (with_bias) result.accel_bias_mps2 = x.tail<3>();
  result.residual_rms = dataResidualRms(fixed, x, data_rows);
  result.R_levelled_world =
      lie::SO3(Eigen::Quaterniond::FromTwoVectors(result.gravity_world, Vector3(0.0, 0.0, -1.0)));
  return result;
}

}  // namespace taiga::imu
