#pragma once
// IMU preintegration on the manifold after Forster, Carlone, Dellaert, Scaramuzza, "On-Manifold
// Preintegration for Real-Time Visual-Inertial Odometry", IEEE T-RO 2017, cited as [Forster] with
// its equation numbers.
//
// Between two states i and j, the IMU samples are summarized by relative motion increments that do
// not depend on the states (Eq. 33):
//   dR_ij = prod_k Exp((w_k - bg) dt)
//   dv_ij = sum_k dR_ik (a_k - ba) dt
//   dp_ij = sum_k dv_ik dt + 1/2 dR_ik (a_k - ba) dt^2
// with w_k, a_k the gyroscope and accelerometer readings in the body (IMU) frame. What is
// modelled: white measurement noise and the biases held constant over the interval at the
// linearization point `bias_hat`; a change of bias estimate is applied to first order through the
// bias Jacobians (Eq. 44). Not modelled: Earth rotation, Coriolis, scale factors and axis
// misalignment, g-sensitivity of the gyroscope.
//
// Error state of the increments, in this order: [dphi (rad); dv (m/s); dp (m)], defined by
// dR_measured = dR_true Exp(dphi), dv_measured = dv_true + dv, dp_measured = dp_true + dp (Eq. 42).

#include <Eigen/Core>

#include "taiga/core/imu_noise.hpp"
#include "taiga/lie/so3.hpp"

namespace taiga::imu {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector9 = Eigen::Matrix<double, 9, 1>;
using Matrix9 = Eigen::Matrix<double, 9, 9>;

/// Accelerometer and gyroscope biases, in the body (IMU) frame: a reading minus the bias is the
/// true specific force or angular rate (plus noise).
struct ImuBias {
  Vector3 accel_mps2 = Vector3::Zero();
  Vector3 gyro_radps = Vector3::Zero();
};

/// Continuous-time noise densities, as IMU datasheets and Kalibr give them.
using taiga::ImuNoise;  // core/imu_noise.hpp

/// Pose and velocity of the body in the world frame (z up, gravity along -z).
struct NavState {
  lie::SO3 R_world_body;
  Vector3 p_world = Vector3::Zero();  ///< position of the body origin, m
  Vector3 v_world = Vector3::Zero();  ///< velocity of the body origin, m/s
};

class Preintegrator {
 public:
  Preintegrator(const ImuBias& bias_hat, const ImuNoise& noise);

  /// Adds one IMU reading held over dt_s (> 0): acceleration (specific force, m/s^2) and angular
  /// rate (rad/s), both in the body frame.
  void integrate(const Vector3& accel_body_mps2, const Vector3& gyro_body_radps, double dt_s);

  double deltaTime() const { return dt_ij_s_; }
  const lie::SO3& deltaR() const { return dR_; }
  const Vector3& deltaV() const { return dv_; }
  const Vector3& deltaP() const { return dp_; }
  const ImuBias& biasHat() const { return bias_hat_; }
  const ImuNoise& noise() const { return noise_; }
  /// Covariance of the increments' error state [dphi; dv; dp] from the measurement noise (Eq. 63).
  const Matrix9& covariance() const { return covariance_; }

  /// Bias Jacobians of the increments at bias_hat (Eq. 69), e.g. dR_dbg = d(dphi)/d(bg).
  const Matrix3& dR_dbg() const { return dR_dbg_; }
  const Matrix3& dV_dba() const { return dV_dba_; }
  const Matrix3& dV_dbg() const { return dV_dbg_; }
  const Matrix3& dP_dba() const { return dP_dba_; }
  const Matrix3& dP_dbg() const { return dP_dbg_; }

  /// The increments for another bias estimate, to first order (Eq. 44).
  lie::SO3 correctedDeltaR(const ImuBias& bias) const;
  Vector3 correctedDeltaV(const ImuBias& bias) const;
  Vector3 correctedDeltaP(const ImuBias& bias) const;

  /// State j predicted from state i with the bias-corrected increments (Eq. 38 with the
  /// increments in place of the true motion).
  NavState predict(const NavState& state_i, const ImuBias& bias,
                   const Vector3& gravity_world) const;

  /// Residual [r_dR; r_dv; r_dp] between the states and the increments (Eq. 45), zero when the
  /// states agree with the measurements.
  Vector9 residual(const NavState& state_i, const NavState& state_j, const ImuBias& bias,
                   const Vector3& gravity_world) const;

 private:
  ImuBias bias_hat_;
  ImuNoise noise_;
  double dt_ij_s_ = 0.0;
  lie::SO3 dR_;
  Vector3 dv_ = Vector3::Zero();
  Vector3 dp_ = Vector3::Zero();
  Matrix9 covariance_ = Matrix9::Zero();
  Matrix3 dR_dbg_ = Matrix3::Zero();
  Matrix3 dV_dba_ = Matrix3::Zero();
  Matrix3 dV_dbg_ = Matrix3::Zero();
  Matrix3 dP_dba_ = Matrix3::Zero();
  Matrix3 dP_dbg_ = Matrix3::Zero();
};

}  // namespace taiga::imu
