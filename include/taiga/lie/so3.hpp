#pragma once
// SO(3), the group of 3D rotations, after Solà, Deray, Atchuthan, "A micro Lie theory for state
// estimation in robotics" (arXiv:1812.01537), cited below as [Solà]: the formulas are those of its
// Appendix B (SO(3)) and Section 4 (Jacobians of the composite operations).
//
// Conventions (declared once here, used by the whole project):
//   tangent theta: rotation vector in rad, Exp(theta) rotates by |theta| about theta/|theta|;
//   right plus  X (+) theta = X * Exp(theta)
//   right minus Y (-) X     = Log(X^-1 * Y)
//   left plus   theta (+) X = Exp(theta) * X
//   left minus  Y (-)_l X   = Log(Y * X^-1)
//   Jacobians of operations are right Jacobians: J^f_X = lim (f(X (+) tau) (-) f(X)) / tau.
//   Optional Jacobian outputs are written when the pointer is not null.
//
// Storage is a unit quaternion; the sign ambiguity q ~ -q is invisible to users.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace taiga::lie {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;

/// Skew-symmetric matrix [v]x such that [v]x * w = v x w.
Matrix3 hat(const Vector3& v);
/// Inverse of hat() for a skew-symmetric matrix.
Vector3 vee(const Matrix3& skew);

class SO3 {
 public:
  /// Identity rotation.
  SO3() = default;
  /// From any non-zero quaternion; it is normalized.
  explicit SO3(const Eigen::Quaterniond& q);
  /// From a rotation matrix (projected onto SO(3) through the quaternion conversion).
  static SO3 fromMatrix(const Matrix3& R);
  /// Rotation of `angle_rad` about `axis` (any non-zero length).
  static SO3 fromAxisAngle(const Vector3& axis, double angle_rad);
  /// R = Rz(yaw) * Ry(pitch) * Rx(roll): roll about x first, then pitch about y, then yaw about z,
  /// all about the fixed (extrinsic) axes.
  static SO3 fromRollPitchYaw(double roll_rad, double pitch_rad, double yaw_rad);

  /// Exponential map R = Exp(theta); J_R_theta = Jr(theta).
  static SO3 Exp(const Vector3& theta, Matrix3* J_R_theta = nullptr);
  /// Logarithmic map theta = Log(R) with |theta| in [0, pi]; J_theta_R = Jr^-1(theta).
  Vector3 Log(Matrix3* J_theta_R = nullptr) const;

  /// Right Jacobian Jr(theta) and its inverse.
  static Matrix3 rightJacobian(const Vector3& theta);
  static Matrix3 rightJacobianInverse(const Vector3& theta);
  /// Left Jacobian Jl(theta) = Jr(-theta) and its inverse.
  static Matrix3 leftJacobian(const Vector3& theta);
  static Matrix3 leftJacobianInverse(const Vector3& theta);

  /// X^-1; J_Xinv_X = -Adj(X).
  SO3 inverse(Matrix3* J_Xinv_X = nullptr) const;
  /// X * Y; J_XY_X = Adj(Y)^T = R_Y^T, J_XY_Y = I.
  SO3 compose(const SO3& Y, Matrix3* J_XY_X = nullptr, Matrix3* J_XY_Y = nullptr) const;
  /// X * p; J_Xp_X = -R [p]x, J_Xp_p = R.
  Vector3 act(const Vector3& p, Matrix3* J_Xp_X = nullptr, Matrix3* J_Xp_p = nullptr) const;
  /// Adjoint matrix, Adj(R) = R.
  Matrix3 adjoint() const { return matrix(); }

  /// X (+) theta; J_Y_X = Adj(Exp(theta))^-1 = Exp(theta)^T, J_Y_theta = Jr(theta).
  SO3 plus(const Vector3& theta, Matrix3* J_Y_X = nullptr, Matrix3* J_Y_theta = nullptr) const;
  /// Y (-) X = Log(X^-1 Y) with `this` as Y; J_d_Y = Jr^-1(d), J_d_X = -Jl^-1(d).
  Vector3 minus(const SO3& X, Matrix3* J_d_Y = nullptr, Matrix3* J_d_X = nullptr) const;
  /// theta (+) X = Exp(theta) * X (left plus).
  SO3 plusLeft(const Vector3& theta) const { return Exp(theta) * *this; }
  /// Y (-)_l X = Log(Y * X^-1) with `this` as Y (left minus).
  Vector3 minusLeft(const SO3& X) const { return (*this * X.inverse()).Log(); }

  SO3 operator*(const SO3& Y) const { return compose(Y); }
  Vector3 operator*(const Vector3& p) const { return act(p); }

  Matrix3 matrix() const { return q_.toRotationMatrix(); }
  const Eigen::Quaterniond& quaternion() const { return q_; }
  /// Rotation angle in [0, pi].
  double angle() const { return Log().norm(); }
  /// The heading: the angle about z of the rotated x axis, atan2(R(1,0), R(0,0)), in (-pi, pi].
  /// The yaw of fromRollPitchYaw when |pitch| < 90 deg.
  double yaw() const;

 private:
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
};

/// X0 (+) [s * (X1 (-) X0)]: geodesic interpolation, s = 0 gives X0 and s = 1 gives X1
/// (thesis Eq. 34). s outside [0, 1] extrapolates along the same geodesic.
SO3 interpolate(const SO3& X0, const SO3& X1, double s);

}  // namespace taiga::lie
