#pragma once
// SE(3), rigid transforms, after [Solà] Appendix D (see so3.hpp for the conventions).
//
// Tangent vector tau = [rho; theta]: rho is the translational part (m), theta the rotation vector
// (rad). Exp(tau) = (Exp(theta), Jl(theta) * rho). A transform T_a_b maps points from frame b into
// frame a: p_a = T_a_b * p_b, and T_a_c = T_a_b * T_b_c.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "taiga/lie/so3.hpp"

namespace taiga::lie {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Matrix4 = Eigen::Matrix4d;
using Matrix36 = Eigen::Matrix<double, 3, 6>;

/// Builds tau = [rho; theta].
inline Vector6 makeTangent(const Vector3& rho, const Vector3& theta) {
  Vector6 tau;
  tau << rho, theta;
  return tau;
}

class SE3 {
 public:
  /// Identity transform.
  SE3() = default;
  SE3(const SO3& rotation, const Vector3& translation) : R_(rotation), t_(translation) {}
  SE3(const Eigen::Quaterniond& q, const Vector3& translation) : R_(q), t_(translation) {}
  /// From a 4x4 homogeneous matrix; the rotation block is projected onto SO(3).
  static SE3 fromMatrix(const Matrix4& T);
  static SE3 fromIsometry(const Eigen::Isometry3d& T) { return fromMatrix(T.matrix()); }

  /// Exponential map; J_T_tau = Jr(tau).
  static SE3 Exp(const Vector6& tau, Matrix6* J_T_tau = nullptr);
  /// Logarithmic map, rotation part with |theta| in [0, pi]; J_tau_T = Jr^-1(tau).
  Vector6 Log(Matrix6* J_tau_T = nullptr) const;

  /// Right Jacobian Jr(tau) = Jl(-tau), and its inverse.
  static Matrix6 rightJacobian(const Vector6& tau);
  static Matrix6 rightJacobianInverse(const Vector6& tau);
  /// Left Jacobian Jl(tau) = [Jl(theta) Q(rho, theta); 0 Jl(theta)], and its inverse.
  static Matrix6 leftJacobian(const Vector6& tau);
  static Matrix6 leftJacobianInverse(const Vector6& tau);

  /// T^-1 = (R^T, -R^T t); J_Tinv_T = -Adj(T).
  SE3 inverse(Matrix6* J_Tinv_T = nullptr) const;
  /// X * Y; J_XY_X = Adj(Y)^-1, J_XY_Y = I.
  SE3 compose(const SE3& Y, Matrix6* J_XY_X = nullptr, Matrix6* J_XY_Y = nullptr) const;
  /// X * p = R p + t; J_Xp_X = [R, -R [p]x], J_Xp_p = R.
  Vector3 act(const Vector3& p, Matrix36* J_Xp_X = nullptr, Matrix3* J_Xp_p = nullptr) const;
  /// Adj(T) = [R, [t]x R; 0, R], so that T * Exp(tau) = Exp(Adj(T) tau) * T.
  Matrix6 adjoint() const;

  /// X (+) tau = X * Exp(tau); J_Y_X = Adj(Exp(tau))^-1, J_Y_tau = Jr(tau).
  SE3 plus(const Vector6& tau, Matrix6* J_Y_X = nullptr, Matrix6* J_Y_tau = nullptr) const;
  /// Y (-) X = Log(X^-1 Y) with `this` as Y; J_d_Y = Jr^-1(d), J_d_X = -Jl^-1(d).
  Vector6 minus(const SE3& X, Matrix6* J_d_Y = nullptr, Matrix6* J_d_X = nullptr) const;
  /// tau (+) X = Exp(tau) * X (left plus).
  SE3 plusLeft(const Vector6& tau) const { return Exp(tau) * *this; }
  /// Y (-)_l X = Log(Y * X^-1) with `this` as Y (left minus).
  Vector6 minusLeft(const SE3& X) const { return (*this * X.inverse()).Log(); }

  SE3 operator*(const SE3& Y) const { return compose(Y); }
  Vector3 operator*(const Vector3& p) const { return act(p); }

  const SO3& rotation() const { return R_; }
  const Vector3& translation() const { return t_; }
  Matrix4 matrix() const;
  Eigen::Isometry3d isometry() const;

 private:
  SO3 R_;
  Vector3 t_ = Vector3::Zero();
};

/// X0 (+) [s * (X1 (-) X0)]: interpolation along the SE(3) geodesic (thesis Eq. 34), s = 0 gives
/// X0 and s = 1 gives X1; s outside [0, 1] extrapolates.
SE3 interpolate(const SE3& X0, const SE3& X1, double s);

}  // namespace taiga::lie
