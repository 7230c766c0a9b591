#include "taiga/calib/lever_arm.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <cmath>

#include "taiga/calib/time_rotation.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/imu/readings.hpp"

namespace taiga::calib {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

struct Step {
  const StampedPose* from = nullptr;
  const StampedPose* to = nullptr;
  Eigen::Index v_from = 0, v_to = 0;  ///< columns of the two velocities
  imu::Preintegrator pre;
};

constexpr Eigen::Index kLever = 0, kAccelBias = 3, kFirstVelocity = 6;

std::vector<Step> steps(const LeverArmInput& in, Eigen::Index* unknowns) {
  std::vector<Step> out;
  Eigen::Index column = kFirstVelocity;
  for (const std::vector<StampedPose>& chain : in.chains) {
    for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
      out.push_back({&chain[k], &chain[k + 1], column + 3 * static_cast<Eigen::Index>(k),
                     column + 3 * static_cast<Eigen::Index>(k + 1),
                     imu::preintegrateReadings(in.imu_body, chain[k].t_s, chain[k + 1].t_s,
                                               in.bias_hat, in.noise)});
    }
    if (chain.size() >= 2) column += 3 * static_cast<Eigen::Index>(chain.size());
  }
  *unknowns = column;
  return out;
}

/// The rows of (2) for one step: 6 x unknowns, and the right-hand side.
void stepRows(const Step& s, const Vector3d& g, Eigen::Ref<MatrixXd> A, Eigen::Ref<VectorXd> b) {
  const Matrix3d R_k = s.from->pose.rotation().matrix();
  const Matrix3d R_k1 = s.to->pose.rotation().matrix();
  const double dt = s.to->t_s - s.from->t_s;
  A.block<3, 3>(0, kLever) = R_k - R_k1;
  A.block<3, 3>(0, kAccelBias) = -R_k * s.pre.dP_dba();
  A.block<3, 3>(0, s.v_from) = -dt * Matrix3d::Identity();
  b.head<3>() = s.from->pose.translation() - s.to->pose.translation() + 0.5 * g * dt * dt +
                R_k * s.pre.deltaP();
  A.block<3, 3>(3, kAccelBias) = -R_k * s.pre.dV_dba();
  A.block<3, 3>(3, s.v_from) = -Matrix3d::Identity();
  A.block<3, 3>(3, s.v_to) = Matrix3d::Identity();
  b.tail<3>() = g * dt + R_k * s.pre.deltaV();
}

}  // namespace

LeverArmEstimate estimateLeverArm(const LeverArmInput& in, double max_sigma_m) {
  Eigen::Index n = 0;
  const std::vector<Step> all = steps(in, &n);
  constexpr std::size_t kMinSteps = 20;
  if (all.size() < kMinSteps)
    throw InputError(fmt::format("lever arm: {} scan-to-scan steps; at least {} are needed",
                                 all.size(), kMinSteps));
  const auto rows = static_cast<Eigen::Index>(6 * all.size());
  MatrixXd A = MatrixXd::Zero(rows, n);
  VectorXd b(rows);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(6 * i);
    stepRows(all[i], in.gravity_odom_mps2, A.middleRows(r, 6), b.segment(r, 6));
  }

  // Weighted least squares; the weights are the residuals' own RMS per kind (positions,
  // velocities), found by solving twice. Rows [left_out_from, left_out_to) are dropped (jackknife).
  // Sparse: each step touches the lever arm, the bias and two velocities, so a 30 s stretch's
  // ~900 unknowns solve in milliseconds (the jackknife solves nine times).
  const Eigen::SparseMatrix<double> A_sparse = A.sparseView();
  Eigen::SparseMatrix<double> flat(n, n);
  flat.setIdentity();
  flat *= 1e-9;  // a flat direction stays where it is
  double sigma_p = 0.01, sigma_v = 0.01;
  VectorXd x;
  Eigen::SparseMatrix<double> N;
  Matrix3d held_prior = Matrix3d::Zero();
  auto solve = [&](Eigen::Index left_out_from = 0, Eigen::Index left_out_to = 0) {
    VectorXd w(rows);
    for (Eigen::Index r = 0; r < rows; ++r) w(r) = (r % 6 < 3) ? 1.0 / sigma_p : 1.0 / sigma_v;
    w.segment(left_out_from, left_out_to - left_out_from).setZero();
    const Eigen::SparseMatrix<double> Aw = w.asDiagonal() * A_sparse;
    N = Eigen::SparseMatrix<double>(Aw.transpose() * Aw) + flat;
    Eigen::SparseMatrix<double> N_held = N;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) N_held.coeffRef(kLever + i, kLever + j) += held_prior(i, j);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N_held);
    x = ldlt.solve(VectorXd(Aw.transpose() * (w.asDiagonal() * b)));
  };
  auto residualRms = [&](int offset) {
    const VectorXd r = A_sparse * x - b;
    double sum = 0.0;
    for (Eigen::Index i = 0; i < rows; ++i)
      if ((i % 6 < 3) == (offset == 0)) sum += r(i) * r(i);
    return std::sqrt(sum / (3.0 * static_cast<double>(all.size())));
  };
  solve();
  sigma_p = std::max(residualRms(0), 1e-6);
  sigma_v = std::max(residualRms(3), 1e-6);
  solve();

  // Covariance of the lever arm (the velocities and bias marginalized), and the directions the
  // motion determined.
  MatrixXd unit = MatrixXd::Zero(n, 3);
  unit.topRows<3>().setIdentity();
  const Matrix3d formal_cov =
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(N).solve(unit).topRows<3>();
  const VectorXd x_all = x;
  LeverArmEstimate e;
  e.formal_sigma_m = formal_cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  // The formal covariance believes every row independent; the registration's errors follow the
  // gait and the terrain over seconds. A delete-one-block jackknife over kBlocks stretches of
  // the walk (Efron & Stein; Kuensch 1989 for dependent data) sees those errors in the spread of
  // the estimates: var = (B - 1) / B * sum_b (d_b - mean)^2. The larger of the two is reported.
  constexpr Eigen::Index kBlocks = 8;
  std::vector<Vector3d> d_blocks;
  for (Eigen::Index block = 0; block < kBlocks; ++block) {
    solve(6 * (static_cast<Eigen::Index>(all.size()) * block / kBlocks),
          6 * (static_cast<Eigen::Index>(all.size()) * (block + 1) / kBlocks));
    d_blocks.push_back(x.segment<3>(kLever));
  }
  Vector3d mean = Vector3d::Zero();
  for (const Vector3d& d : d_blocks) mean += d / kBlocks;
  Matrix3d jackknife_cov = Matrix3d::Zero();
  for (const Vector3d& d : d_blocks)
    jackknife_cov += (d - mean) * (d - mean).transpose() * (kBlocks - 1.0) / kBlocks;
  e.jackknife_sigma_m = jackknife_cov.diagonal().cwiseSqrt();
  const Matrix3d cov = jackknife_cov.trace() > formal_cov.trace() ? jackknife_cov : formal_cov;
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(cov);
  std::vector<Vector3d> held;
  for (int i = 0; i < 3; ++i) {
    if (std::sqrt(std::max(0.0, eig.eigenvalues()(i))) <= max_sigma_m) continue;
    held.push_back(eig.eigenvectors().col(i));
    held_prior += 1e12 * held.back() * held.back().transpose();  // held at the configured value
  }
  e.observable = axesNotHeld(held);
  x = x_all;
  if (!held_prior.isZero()) solve();
  e.correction_m = x.segment<3>(kLever);
  e.sigma_m = e.formal_sigma_m.cwiseMax(e.jackknife_sigma_m);
  e.accel_bias_mps2 = x.segment<3>(kAccelBias);
  e.position_rms_m = residualRms(0);
  e.velocity_rms_mps = residualRms(3);
  e.steps = all.size();
  return e;
}

}  // namespace taiga::calib
