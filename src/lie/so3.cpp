#include "taiga/lie/so3.hpp"

#include <cassert>
#include <cmath>
#include <limits>

namespace taiga::lie {
namespace {

// Below this angle the closed forms lose digits to cancellation (relative error ~ eps / theta^2),
// so the coefficients come from their Taylor series instead; the first omitted term is
// O(theta^6) ~ 1e-12 times a coefficient below 1e-4, i.e. below double precision.
constexpr double kSmallAngle = 1e-2;

// (1 - cos t) / t^2
double coeffOneMinusCos(double t) {
  const double t2 = t * t;
  if (t < kSmallAngle) return 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
  return (1.0 - std::cos(t)) / t2;
}

// (t - sin t) / t^3
double coeffTMinusSin(double t) {
  const double t2 = t * t;
  if (t < kSmallAngle) return 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  return (t - std::sin(t)) / (t2 * t);
}

// 1/t^2 - (1 + cos t) / (2 t sin t), written with cot(t/2) = (1 + cos t) / sin t so that it
// stays finite at t = pi (it equals 1/pi^2 there).
double coeffInverseJacobian(double t) {
  const double t2 = t * t;
  if (t < kSmallAngle) return 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  return 1.0 / t2 - 1.0 / (2.0 * t * std::tan(0.5 * t));
}

}  // namespace

Matrix3 hat(const Vector3& v) {
  Matrix3 m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Vector3 vee(const Matrix3& skew) { return Vector3(skew(2, 1), skew(0, 2), skew(1, 0)); }

SO3::SO3(const Eigen::Quaterniond& q) : q_(q) {
  assert(q.norm() > 0.0);
  // A quaternion that is already unit to rounding is kept as it is, so that rotations written
  // to files with full precision read back bit for bit.
  if (std::abs(q_.squaredNorm() - 1.0) > 4.0 * std::numeric_limits<double>::epsilon())
    q_.normalize();
}

SO3 SO3::fromMatrix(const Matrix3& R) { return SO3(Eigen::Quaterniond(R)); }

double SO3::yaw() const {
  const Matrix3 R = matrix();
  return std::atan2(R(1, 0), R(0, 0));
}

SO3 SO3::fromAxisAngle(const Vector3& axis, double angle_rad) {
  return Exp(axis.normalized() * angle_rad);
}

SO3 SO3::fromRollPitchYaw(double roll_rad, double pitch_rad, double yaw_rad) {
  return Exp(Vector3::UnitZ() * yaw_rad) * Exp(Vector3::UnitY() * pitch_rad) *
         Exp(Vector3::UnitX() * roll_rad);
}

SO3 SO3::Exp(const Vector3& theta, Matrix3* J_R_theta) {
  // q = [cos(t/2), sin(t/2) * theta / t], with sin(t/2)/t from its series near zero.
  const double t = theta.norm();
  const double half_sinc =
      t < kSmallAngle ? 0.5 - t * t / 48.0 + t * t * t * t / 3840.0 : std::sin(0.5 * t) / t;
  const Vector3 v = half_sinc * theta;
  if (J_R_theta) *J_R_theta = rightJacobian(theta);
  SO3 result;
  result.q_ = Eigen::Quaterniond(std::cos(0.5 * t), v.x(), v.y(), v.z());
  result.q_.normalize();
  return result;
}

Vector3 SO3::Log(Matrix3* J_theta_R) const {
  // theta = 2 atan2(|v|, w) * v / |v| on the hemisphere w >= 0, which keeps |theta| <= pi.
  // atan2 keeps full relative accuracy both near pi (w -> 0) and near zero (where it returns
  // ~ n / w), so only n = 0 itself needs the limit 2 / w.
  Eigen::Quaterniond q = q_;
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vector3 v = q.vec();
  const double n = v.norm();
  const double w = q.w();
  const double scale = n > 0.0 ? 2.0 * std::atan2(n, w) / n : 2.0 / w;
  const Vector3 theta = scale * v;
  if (J_theta_R) *J_theta_R = rightJacobianInverse(theta);
  return theta;
}

// Jr(theta) = I - (1 - cos t)/t^2 [theta]x + (t - sin t)/t^3 [theta]x^2
Matrix3 SO3::rightJacobian(const Vector3& theta) {
  const double t = theta.norm();
  const Matrix3 W = hat(theta);
  return Matrix3::Identity() - coeffOneMinusCos(t) * W + coeffTMinusSin(t) * W * W;
}

// Jr^-1(theta) = I + 1/2 [theta]x + (1/t^2 - (1 + cos t)/(2 t sin t)) [theta]x^2
Matrix3 SO3::rightJacobianInverse(const Vector3& theta) {
  const double t = theta.norm();
  const Matrix3 W = hat(theta);
  return Matrix3::Identity() + 0.5 * W + coeffInverseJacobian(t) * W * W;
}

Matrix3 SO3::leftJacobian(const Vector3& theta) { return rightJacobian(-theta); }

Matrix3 SO3::leftJacobianInverse(const Vector3& theta) { return rightJacobianInverse(-theta); }

SO3 SO3::inverse(Matrix3* J_Xinv_X) const {
  if (J_Xinv_X) *J_Xinv_X = -adjoint();
  SO3 result;
  result.q_ = q_.conjugate();
  return result;
}

SO3 SO3::compose(const SO3& Y, Matrix3* J_XY_X, Matrix3* J_XY_Y) const {
  if (J_XY_X) *J_XY_X = Y.matrix().transpose();
  if (J_XY_Y) J_XY_Y->setIdentity();
  SO3 result;
  result.q_ = (q_ * Y.q_).normalized();
  return result;
}

Vector3 SO3::act(const Vector3& p, Matrix3* J_Xp_X, Matrix3* J_Xp_p) const {
  const Matrix3 R = matrix();
  if (J_Xp_X) *J_Xp_X = -R * hat(p);
  if (J_Xp_p) *J_Xp_p = R;
  return R * p;
}

SO3 SO3::plus(const Vector3& theta, Matrix3* J_Y_X, Matrix3* J_Y_theta) const {
  const SO3 delta = Exp(theta, J_Y_theta);
  if (J_Y_X) *J_Y_X = delta.matrix().transpose();
  return compose(delta);
}

Vector3 SO3::minus(const SO3& X, Matrix3* J_d_Y, Matrix3* J_d_X) const {
  const Vector3 d = (X.inverse() * *this).Log();
  if (J_d_Y) *J_d_Y = rightJacobianInverse(d);
  if (J_d_X) *J_d_X = -leftJacobianInverse(d);
  return d;
}

SO3 interpolate(const SO3& X0, const SO3& X1, double s) { return X0.plus(s * X1.minus(X0)); }

}  // namespace taiga::lie
