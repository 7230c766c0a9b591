#include "taiga/sim/motion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

/// f(t) = A sin(w t + p) with its derivative.
struct Sine {
  double value, rate;
};
Sine sine(double amplitude, double frequency_hz, double phase, double t) {
  const double w = 2.0 * kPi * frequency_hz;
  return {amplitude * std::sin(w * t + phase), amplitude * w * std::cos(w * t + phase)};
}
double sineAcc(double amplitude, double frequency_hz, double phase, double t) {
  const double w = 2.0 * kPi * frequency_hz;
  return -amplitude * w * w * std::sin(w * t + phase);
}
}  // namespace

WalkingMotion::WalkingMotion(const MotionParams& params, double duration_s, std::uint64_t seed,
                             Terrain terrain)
    : params_(params), terrain_(std::move(terrain)) {
  Rng rng(streamSeed(seed, "motion"));
  for (int k = 0; k < 2; ++k) {
    a_[k] = params.shape_perturbation * rng.uniform(0.5, 1.0) / (k + 2);
    b_[k] = params.shape_perturbation * rng.uniform(0.5, 1.0) / (k + 2);
    phi_[k] = rng.uniform(0.0, 2.0 * kPi);
    psi_[k] = rng.uniform(0.0, 2.0 * kPi);
  }
  for (double& p : phases_) p = rng.uniform(0.0, 2.0 * kPi);
  // Perimeter of the unit loop (Rx = 1), then scale to the wanted length.
  rx_m_ = 1.0;
  ry_m_ = params.loop_aspect;
  double unit_perimeter = 0.0;
  Eigen::Vector2d prev, c;
  constexpr int kSteps = 4000;
  for (int i = 0; i <= kSteps; ++i) {
    curve(2.0 * kPi * i / kSteps, &c, nullptr, nullptr);
    if (i > 0) unit_perimeter += (c - prev).norm();
    prev = c;
  }
  const double length_m = std::clamp(0.95 * params.speed_mps * duration_s, 25.0,
                                     std::max(25.0, params.max_loop_length_m));
  rx_m_ = length_m / unit_perimeter;
  ry_m_ = params.loop_aspect * rx_m_;
  curve(0.0, &offset_, nullptr, nullptr);
  period_s_ = length_m / params.speed_mps;
  omega_ = 2.0 * kPi / period_s_;
  speed_harmonic_ = std::max(1, static_cast<int>(std::round(period_s_ / 15.0)));
}

void WalkingMotion::curve(double u, Eigen::Vector2d* c, Eigen::Vector2d* dc,
                          Eigen::Vector2d* ddc) const {
  // Wiggles scale with each axis' radius so that thin loops (strip road) stay thin.
  double x = rx_m_ * std::cos(u), y = ry_m_ * std::sin(u);
  double dx = -rx_m_ * std::sin(u), dy = ry_m_ * std::cos(u);
  double ddx = -rx_m_ * std::cos(u), ddy = -ry_m_ * std::sin(u);
  for (int i = 0; i < 2; ++i) {
    const double k = i + 2;
    const double ax = a_[i] * rx_m_, by = b_[i] * ry_m_;
    x += ax * std::cos(k * u + phi_[i]);
    dx -= ax * k * std::sin(k * u + phi_[i]);
    ddx -= ax * k * k * std::cos(k * u + phi_[i]);
    y += by * std::sin(k * u + psi_[i]);
    dy += by * k * std::cos(k * u + psi_[i]);
    ddy -= by * k * k * std::sin(k * u + psi_[i]);
  }
  if (c) *c = Eigen::Vector2d(x, y);
  if (dc) *dc = Eigen::Vector2d(dx, dy);
  if (ddc) *ddc = Eigen::Vector2d(ddx, ddy);
}

MotionState WalkingMotion::at(double t) const {
  const MotionParams& p = params_;
  // Phase along the loop and its derivatives.
  const double m = speed_harmonic_, s = p.speed_variation;
  const double u = omega_ * t + (s / m) * std::sin(m * omega_ * t);
  const double du = omega_ * (1.0 + s * std::cos(m * omega_ * t));
  const double ddu = -omega_ * omega_ * m * s * std::sin(m * omega_ * t);
  Eigen::Vector2d c, dc, ddc;
  curve(u, &c, &dc, &ddc);
  c -= offset_;
  const Eigen::Vector2d v_path = dc * du;
  const Eigen::Vector2d a_path = ddc * du * du + dc * ddu;

  // Horizontal sway and vertical bob of the gait.
  const double f_step = p.step_frequency_hz;
  const Sine sx = sine(p.sway_m, 0.5 * f_step, phases_[0], t);
  const Sine sy = sine(p.sway_m, 0.37 * f_step, phases_[1], t);
  const Sine bob = sine(p.bob_m, f_step, phases_[2], t);
  Eigen::Vector2d grad;
  Eigen::Matrix2d hess;
  const double ground = terrain_.smoothHeight(c.x(), c.y(), &grad, &hess);

  MotionState state;
  state.t_s = t;
  const Eigen::Vector3d position(c.x() + sx.value, c.y() + sy.value,
                                 ground + p.sensor_height_m + bob.value);
  state.v_world =
      Eigen::Vector3d(v_path.x() + sx.rate, v_path.y() + sy.rate, grad.dot(v_path) + bob.rate);
  state.a_world = Eigen::Vector3d(
      a_path.x() + sineAcc(p.sway_m, 0.5 * f_step, phases_[0], t),
      a_path.y() + sineAcc(p.sway_m, 0.37 * f_step, phases_[1], t),
      v_path.dot(hess * v_path) + grad.dot(a_path) + sineAcc(p.bob_m, f_step, phases_[2], t));

  // Orientation: yaw follows the path heading plus look-around swings; roll and pitch sway.
  const double heading = std::atan2(dc.y(), dc.x());
  const double heading_rate = (dc.x() * ddc.y() - dc.y() * ddc.x()) / dc.squaredNorm() * du;
  const Sine look_slow = sine(p.look_around_deg * kDeg, 0.11, phases_[3], t);
  const Sine look_fast = sine(p.look_around_fast_deg * kDeg, 0.43, phases_[4], t);
  const Sine roll_s = sine(p.roll_sway_deg * kDeg, 0.5 * f_step, phases_[5], t);
  const Sine pitch_s = sine(p.pitch_sway_deg * kDeg, f_step, phases_[0] + 1.0, t);
  const double yaw = heading + look_slow.value + look_fast.value;
  const double yaw_rate = heading_rate + look_slow.rate + look_fast.rate;
  const double roll = roll_s.value, roll_rate = roll_s.rate;
  const double pitch = p.pitch_mean_deg * kDeg + pitch_s.value, pitch_rate = pitch_s.rate;
  state.T_world_body = lie::SE3(lie::SO3::fromRollPitchYaw(roll, pitch, yaw), position);
  // Body angular rate of R = Rz(yaw) Ry(pitch) Rx(roll).
  const double sr = std::sin(roll), cr = std::cos(roll), sp = std::sin(pitch), cp = std::cos(pitch);
  state.omega_body =
      Eigen::Vector3d(roll_rate - yaw_rate * sp, pitch_rate * cr + yaw_rate * sr * cp,
                      -pitch_rate * sr + yaw_rate * cr * cp);
  return state;
}

std::vector<Eigen::Vector2d> WalkingMotion::loopPolyline(double spacing_m) const {
  const double length = period_s_ * params_.speed_mps;
  const int n = std::max(16, static_cast<int>(std::ceil(1.3 * length / spacing_m)));
  std::vector<Eigen::Vector2d> points;
  points.reserve(n);
  Eigen::Vector2d c;
  for (int i = 0; i < n; ++i) {
    curve(2.0 * kPi * i / n, &c, nullptr, nullptr);
    points.push_back(c - offset_);
  }
  return points;
}

Eigen::Vector2d WalkingMotion::loopCenter() const {
  const auto points = loopPolyline(1.0);
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return 0.5 * (lo + hi);
}

double WalkingMotion::loopHalfExtent_m() const {
  const auto points = loopPolyline(1.0);
  const Eigen::Vector2d center = loopCenter();
  double extent = 0.0;
  for (const auto& p : points) extent = std::max(extent, (p - center).cwiseAbs().maxCoeff());
  return extent;
}

}  // namespace taiga::sim
