#include "taiga/imu/preintegration.hpp"

#include <stdexcept>

namespace taiga::imu {

Preintegrator::Preintegrator(const ImuBias& bias_hat, const ImuNoise& noise)
    : bias_hat_(bias_hat), noise_(noise) {}

void Preintegrator::integrate(const Vector3& accel_body_mps2, const Vector3& gyro_body_radps,
                              double dt_s) {
  if (!(dt_s > 0.0)) throw std::invalid_argument("Preintegrator::integrate: dt_s must be positive");
  const Vector3 accel = accel_body_mps2 - bias_hat_.accel_mps2;
  const Vector3 theta = (gyro_body_radps - bias_hat_.gyro_radps) * dt_s;
  const lie::SO3 dR_step = lie::SO3::Exp(theta);
  const Matrix3 Jr_step = lie::SO3::rightJacobian(theta);
  const Matrix3 dR_ik = dR_.matrix();  // rotation up to the start of this step
  const Matrix3 dR_step_T = dR_step.matrix().transpose();
  const Matrix3 dR_accel_hat = dR_ik * lie::hat(accel);
  const double dt2 = dt_s * dt_s;

  // Noise propagation [Forster] Eq. 62-63: eta_{k+1} = A eta_k + B_g n_g + B_a n_a, with the
  // discrete noise covariance sigma^2 / dt of white noise of density sigma.
  Matrix9 A = Matrix9::Identity();
  A.block<3, 3>(0, 0) = dR_step_T;
  A.block<3, 3>(3, 0) = -dR_accel_hat * dt_s;
  A.block<3, 3>(6, 0) = -0.5 * dR_accel_hat * dt2;
  A.block<3, 3>(6, 3) = Matrix3::Identity() * dt_s;
  Eigen::Matrix<double, 9, 3> B_gyro = Eigen::Matrix<double, 9, 3>::Zero();
  B_gyro.block<3, 3>(0, 0) = Jr_step * dt_s;
  Eigen::Matrix<double, 9, 3> B_accel = Eigen::Matrix<double, 9, 3>::Zero();
  B_accel.block<3, 3>(3, 0) = dR_ik * dt_s;
  B_accel.block<3, 3>(6, 0) = 0.5 * dR_ik * dt2;
  const double gyro_var = noise_.gyro_noise_density * noise_.gyro_noise_density / dt_s;
  const double accel_var = noise_.accel_noise_density * noise_.accel_noise_density / dt_s;
  covariance_ = A * covariance_ * A.transpose() + gyro_var * B_gyro * B_gyro.transpose() +
                accel_var * B_accel * B_accel.transpose();

  // Bias Jacobians [Forster] Eq. 69 (Appendix B), each from the previous values.
  dP_dba_ += dV_dba_ * dt_s - 0.5 * dR_ik * dt2;
  dP_dbg_ += dV_dbg_ * dt_s - 0.5 * dR_accel_hat * dR_dbg_ * dt2;
  dV_dba_ -= dR_ik * dt_s;
  dV_dbg_ -= dR_accel_hat * dR_dbg_ * dt_s;
  dR_dbg_ = dR_step_T * dR_dbg_ - Jr_step * dt_s;

  // Increments [Forster] Eq. 33: position first, as it uses the velocity before this step.
  dp_ += dv_ * dt_s + 0.5 * dR_ik * accel * dt2;
  dv_ += dR_ik * accel * dt_s;
  dR_ = dR_ * dR_step;
  dt_ij_s_ += dt_s;
}

lie::SO3 Preintegrator::correctedDeltaR(const ImuBias& bias) const {
  return dR_ * lie::SO3::Exp(dR_dbg_ * (bias.gyro_radps - bias_hat_.gyro_radps));
}

Vector3 Preintegrator::correctedDeltaV(const ImuBias& bias) const {
  return dv_ + dV_dba_ * (bias.accel_mps2 - bias_hat_.accel_mps2) +
         dV_dbg_ * (bias.gyro_radps - bias_hat_.gyro_radps);
}

Vector3 Preintegrator::correctedDeltaP(const ImuBias& bias) const {
  return dp_ + dP_dba_ * (bias.accel_mps2 - bias_hat_.accel_mps2) +
         dP_dbg_ * (bias.gyro_radps - bias_hat_.gyro_radps);
}

NavState Preintegrator::predict(const NavState& state_i, const ImuBias& bias,
                                const Vector3& gravity_world) const {
  const double dt = dt_ij_s_;
  NavState state_j;
  state_j.R_world_body = state_i.R_world_body * correctedDeltaR(bias);
  state_j.v_world =
      state_i.v_world + gravity_world * dt + state_i.R_world_body * correctedDeltaV(bias);
  state_j.p_world = state_i.p_world + state_i.v_world * dt + 0.5 * gravity_world * dt * dt +
                    state_i.R_world_body * correctedDeltaP(bias);
  return state_j;
}

Vector9 Preintegrator::residual(const NavState& state_i, const NavState& state_j,
                                const ImuBias& bias, const Vector3& gravity_world) const {
  const double dt = dt_ij_s_;
  const lie::SO3 R_body_world_i = state_i.R_world_body.inverse();
  Vector9 r;
  r.segment<3>(0) = (correctedDeltaR(bias).inverse() * R_body_world_i * state_j.R_world_body).Log();
  r.segment<3>(3) = R_body_world_i * (state_j.v_world - state_i.v_world - gravity_world * dt) -
                    correctedDeltaV(bias);
  r.segment<3>(6) = R_body_world_i * (state_j.p_world - state_i.p_world - state_i.v_world * dt -
                                      0.5 * gravity_world * dt * dt) -
                    correctedDeltaP(bias);
  return r;
}

}  // namespace taiga::imu
