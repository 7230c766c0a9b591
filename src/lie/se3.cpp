#include "taiga/lie/se3.hpp"

#include <cmath>

namespace taiga::lie {
namespace {

constexpr double kSmallAngle = 1e-2;

// Q(rho, theta), the coupling block of the SE(3) left Jacobian ([Solà] App. D; Barfoot,
// "State Estimation for Robotics", Eq. 7.86):
//   Q = 1/2 P + c1 (W P + P W + W P W) + c2 (W W P + P W W - 3 W P W)
//         + c3 (W P W W + W W P W),   with W = [theta]x, P = [rho]x and
//   c1 = (t - sin t)/t^3, c2 = (t^2 + 2 cos t - 2)/(2 t^4), c3 = (2t - 3 sin t + t cos t)/(2 t^5).
// The coefficients use their Taylor series below kSmallAngle, where the closed forms cancel.
Matrix3 couplingQ(const Vector3& rho, const Vector3& theta) {
  const double t = theta.norm();
  const double t2 = t * t;
  double c1, c2, c3;
  if (t < kSmallAngle) {
    c1 = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
    c2 = 1.0 / 24.0 - t2 / 720.0 + t2 * t2 / 40320.0;
    c3 = 1.0 / 120.0 - t2 / 2520.0 + t2 * t2 / 120960.0;
  } else {
    const double s = std::sin(t), c = std::cos(t);
    c1 = (t - s) / (t2 * t);
    c2 = (t2 + 2.0 * c - 2.0) / (2.0 * t2 * t2);
    c3 = (2.0 * t - 3.0 * s + t * c) / (2.0 * t2 * t2 * t);
  }
  const Matrix3 W = hat(theta);
  const Matrix3 P = hat(rho);
  const Matrix3 WP = W * P, PW = P * W, WPW = W * P * W;
  return 0.5 * P + c1 * (WP + PW + WPW) + c2 * (W * WP + PW * W - 3.0 * WPW) +
         c3 * (WPW * W + W * WPW);
}

Vector3 rhoOf(const Vector6& tau) { return tau.head<3>(); }
Vector3 thetaOf(const Vector6& tau) { return tau.tail<3>(); }

}  // namespace

SE3 SE3::fromMatrix(const Matrix4& T) {
  return SE3(SO3::fromMatrix(T.topLeftCorner<3, 3>()), T.topRightCorner<3, 1>());
}

SE3 SE3::Exp(const Vector6& tau, Matrix6* J_T_tau) {
  const Vector3 theta = thetaOf(tau);
  if (J_T_tau) *J_T_tau = rightJacobian(tau);
  return SE3(SO3::Exp(theta), SO3::leftJacobian(theta) * rhoOf(tau));
}

Vector6 SE3::Log(Matrix6* J_tau_T) const {
  const Vector3 theta = R_.Log();
  const Vector6 tau = makeTangent(SO3::leftJacobianInverse(theta) * t_, theta);
  if (J_tau_T) *J_tau_T = rightJacobianInverse(tau);
  return tau;
}

Matrix6 SE3::leftJacobian(const Vector6& tau) {
  const Matrix3 Jl = SO3::leftJacobian(thetaOf(tau));
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = Jl;
  J.bottomRightCorner<3, 3>() = Jl;
  J.topRightCorner<3, 3>() = couplingQ(rhoOf(tau), thetaOf(tau));
  return J;
}

// Block inverse of [A Q; 0 A]: [A^-1, -A^-1 Q A^-1; 0, A^-1].
Matrix6 SE3::leftJacobianInverse(const Vector6& tau) {
  const Matrix3 Jl_inv = SO3::leftJacobianInverse(thetaOf(tau));
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = Jl_inv;
  J.bottomRightCorner<3, 3>() = Jl_inv;
  J.topRightCorner<3, 3>() = -Jl_inv * couplingQ(rhoOf(tau), thetaOf(tau)) * Jl_inv;
  return J;
}

Matrix6 SE3::rightJacobian(const Vector6& tau) { return leftJacobian(-tau); }

Matrix6 SE3::rightJacobianInverse(const Vector6& tau) { return leftJacobianInverse(-tau); }

SE3 SE3::inverse(Matrix6* J_Tinv_T) const {
  if (J_Tinv_T) *J_Tinv_T = -adjoint();
  const SO3 R_inv = R_.inverse();
  return SE3(R_inv, -(R_inv * t_));
}

SE3 SE3::compose(const SE3& Y, Matrix6* J_XY_X, Matrix6* J_XY_Y) const {
  if (J_XY_X) *J_XY_X = Y.inverse().adjoint();
  if (J_XY_Y) J_XY_Y->setIdentity();
  return SE3(R_ * Y.R_, t_ + R_ * Y.t_);
}

Vector3 SE3::act(const Vector3& p, Matrix36* J_Xp_X, Matrix3* J_Xp_p) const {
  const Matrix3 R = R_.matrix();
  if (J_Xp_X) {
    J_Xp_X->leftCols<3>() = R;
    J_Xp_X->rightCols<3>() = -R * hat(p);
  }
  if (J_Xp_p) *J_Xp_p = R;
  return R * p + t_;
}

Matrix6 SE3::adjoint() const {
  const Matrix3 R = R_.matrix();
  Matrix6 Ad = Matrix6::Zero();
  Ad.topLeftCorner<3, 3>() = R;
  Ad.bottomRightCorner<3, 3>() = R;
  Ad.topRightCorner<3, 3>() = hat(t_) * R;
  return Ad;
}

SE3 SE3::plus(const Vector6& tau, Matrix6* J_Y_X, Matrix6* J_Y_tau) const {
  const SE3 delta = Exp(tau, J_Y_tau);
  if (J_Y_X) *J_Y_X = delta.inverse().adjoint();
  return compose(delta);
}

Vector6 SE3::minus(const SE3& X, Matrix6* J_d_Y, Matrix6* J_d_X) const {
  const Vector6 d = (X.inverse() * *this).Log();
  if (J_d_Y) *J_d_Y = rightJacobianInverse(d);
  if (J_d_X) *J_d_X = -leftJacobianInverse(d);
  return d;
}

Matrix4 SE3::matrix() const {
  Matrix4 T = Matrix4::Identity();
  T.topLeftCorner<3, 3>() = R_.matrix();
  T.topRightCorner<3, 1>() = t_;
  return T;
}

Eigen::Isometry3d SE3::isometry() const { return Eigen::Isometry3d(matrix()); }

SE3 interpolate(const SE3& X0, const SE3& X1, double s) { return X0.plus(s * X1.minus(X0)); }

}  // namespace taiga::lie
