// The handheld walk. Horizontal path c(u), u in [0, 2 pi) (closed, C-infinity):
//   one loop:   c(u) = (Rx cos u + sum_k a_k cos(k u + phi_k), Ry sin u + sum_k b_k sin(k u + psi_k))
//   cloverleaf: c(u) = rho(u) (cos ku, sin ku) + wiggles, rho(u) = R(u) sin(n u / 2), with
//               k = 1/2 for an odd number of lobes n and k = 1 for n = 4 (a rose curve: every lobe
//               passes through the start), R(u) = R0 (1 + e cos(u + phase)) makes lobes differ.
// The path is walked at nearly constant speed by an arc-length reparametrization u = v + g(v), g a
// truncated Fourier series fitted to the inverse of the arc length (smooth and periodic, so the
// derivatives stay exact). The phase v follows the walk clock tau (the time spent walking):
//   v = W tau + (s/m) sin(m W tau)                       (speed changes),
//   tau(t) = t - sum_i integral P_i                       (pauses: P_i smooth plateaus, so the
//                                                          speed goes smoothly to zero and back).
// Height = smooth terrain + sensor height + gait bob; gait bob and sway shrink while standing.
// Yaw = path heading + look-around swings + fast turns (smooth plateaus in yaw whose ramp time is
// fitted so the total yaw rate peaks at the drawn rate).
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "motion_models.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim::detail {
namespace {
constexpr double kPi = std::numbers::pi;
/// Harmonics of the arc-length correction g(v).
constexpr int kArcHarmonics = 64;
// A stadium's ends (loop_straightness > 0) turn the arc length's rate over u sharply: more terms.
constexpr int kStadiumArcHarmonics = 256;

class HandheldMotion final : public TrajectoryModel {
 public:
  HandheldMotion(const MotionParams& params, double duration_s, std::uint64_t seed,
                 Terrain terrain);

  MotionState at(double t) const override;
  std::vector<Eigen::Vector2d> pathPolyline(double spacing_m) const override;
  double loopPeriod_s() const override { return loop_period_s_; }
  std::vector<StandStill> standStills() const override {
    std::vector<StandStill> out;
    for (const Plateau& p : pauses_.plateaus())
      out.push_back({p.holdStart_s(), p.holdEnd_s(), StandStill::Kind::kPause});
    return out;
  }

 private:
  /// c(u) and its derivatives with respect to u (before the c(0) offset).
  void curve(double u, Eigen::Vector2d* c, Eigen::Vector2d* dc, Eigen::Vector2d* ddc) const;
  /// Arc-length correction g(v), g', g''.
  Jet arcCorrection(double v) const;
  /// Walking phase u(t) with its time derivatives.
  Jet phase(double t) const;
  /// Yaw rate without the fast turns, rad/s (to fit the turns' ramps).
  double baseYawRate(double t) const;
  void fitArcLength();
  void drawPauses(double duration_s, std::uint64_t seed);
  void drawFastTurns(double duration_s, std::uint64_t seed);

  MotionParams params_;
  Terrain terrain_;
  double rx_m_ = 1.0, ry_m_ = 1.0;  ///< loop radii, or R0 (rx) of a cloverleaf
  double a_[2]{}, phi_[2]{}, b_[2]{}, psi_[2]{};
  double lobe_phase_ = 0.0;
  Eigen::Vector2d offset_ = Eigen::Vector2d::Zero();  ///< c(0)
  double length_m_ = 0.0;
  double walk_period_s_ = 60.0;  ///< walking time for one round, s (pauses excluded)
  double loop_period_s_ = 60.0;  ///< real time for the first round, s
  double omega_ = 0.1;           ///< W, rad/s
  int speed_harmonic_ = 1;       ///< m
  double phases_[6]{};           ///< gait and look-around phases
  int arc_harmonics_ = kArcHarmonics;
  double arc_cos_[kStadiumArcHarmonics + 1]{}, arc_sin_[kStadiumArcHarmonics + 1]{};
  PlateauTrain pauses_;  ///< unit plateaus: the share of standing still
  PlateauTrain turns_;   ///< plateaus of yaw offset, rad
};

HandheldMotion::HandheldMotion(const MotionParams& params, double duration_s, std::uint64_t seed,
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
  lobe_phase_ = Rng(streamSeed(seed, "motion-lobes")).uniform(0.0, 2.0 * kPi);
  drawPauses(duration_s, seed);

  // Perimeter of the unit path (Rx = 1), then scale to the wanted length: the walking time in
  // the first 95 % of the duration at the mean speed.
  rx_m_ = 1.0;
  ry_m_ = params.loop_aspect;
  double unit_perimeter = 0.0;
  Eigen::Vector2d prev, c;
  constexpr int kSteps = 8000;
  for (int i = 0; i <= kSteps; ++i) {
    curve(2.0 * kPi * i / kSteps, &c, nullptr, nullptr);
    if (i > 0) unit_perimeter += (c - prev).norm();
    prev = c;
  }
  const double t_round = 0.95 * duration_s;
  const double walking_s = t_round - pauses_.integral(t_round).v;
  length_m_ = std::clamp(params.speed_mps * walking_s, 25.0, std::max(25.0, params.max_loop_length_m));
  rx_m_ = length_m_ / unit_perimeter;
  ry_m_ = params.loop_aspect * rx_m_;
  curve(0.0, &offset_, nullptr, nullptr);
  fitArcLength();
  walk_period_s_ = length_m_ / params.speed_mps;
  omega_ = 2.0 * kPi / walk_period_s_;
  speed_harmonic_ = std::max(1, static_cast<int>(std::round(walk_period_s_ / 15.0)));

  // First return to the start: tau(t) = walk period (tau is non-decreasing).
  double lo = walk_period_s_, hi = walk_period_s_ + pauses_.integral(1e12).v + 1.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (mid - pauses_.integral(mid).v < walk_period_s_ ? lo : hi) = mid;
  }
  loop_period_s_ = hi;
  drawFastTurns(duration_s, seed);
}

void HandheldMotion::drawPauses(double duration_s, std::uint64_t seed) {
  std::vector<Plateau> pauses;
  if (params_.pause_interval_s > 0.0) {
    Rng rng(streamSeed(seed, "motion-pauses"));
    // No pause around the end of the first round, so that the walk is back at its start at
    // 95 % of the duration exactly.
    const double t_round = 0.95 * duration_s;
    double t = 0.0;
    while (true) {
      Plateau p;
      p.t0_s = t + params_.pause_interval_s * rng.uniform(0.5, 1.5);
      p.ramp_s = params_.pause_ramp_s;
      p.hold_s = rng.uniform(params_.pause_min_s, params_.pause_max_s);
      if (p.t0_s > duration_s + 60.0) break;
      if (p.end_s() < t_round - 1.0 || p.t0_s > t_round + 1.0) pauses.push_back(p);
      t = p.end_s();
    }
  }
  pauses_ = PlateauTrain(std::move(pauses));
}

void HandheldMotion::fitArcLength() {
  // Arc length s(u) on a fine grid, then u(v) at equally spaced v = 2 pi s / L, then the Fourier
  // coefficients of g(v) = u(v) - v (a periodic function) by the trapezoidal rule.
  constexpr int kGrid = 16384, kSamples = 1024;
  std::vector<double> s(kGrid + 1, 0.0);
  Eigen::Vector2d dc, dc_prev;
  curve(0.0, nullptr, &dc_prev, nullptr);
  for (int i = 1; i <= kGrid; ++i) {
    curve(2.0 * kPi * i / kGrid, nullptr, &dc, nullptr);
    s[i] = s[i - 1] + 0.5 * (dc.norm() + dc_prev.norm()) * 2.0 * kPi / kGrid;
    dc_prev = dc;
  }
  const double total = s[kGrid];
  std::vector<double> g(kSamples);
  int j = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double target = total * k / kSamples;
    while (j < kGrid - 1 && s[j + 1] < target) ++j;
    const double f = (target - s[j]) / std::max(1e-300, s[j + 1] - s[j]);
    const double u = 2.0 * kPi * (j + f) / kGrid;
    g[k] = u - 2.0 * kPi * k / kSamples;
  }
  arc_harmonics_ = params_.loop_straightness > 0.0 ? kStadiumArcHarmonics : kArcHarmonics;
  for (int h = 0; h <= arc_harmonics_; ++h) {
    double ca = 0.0, sa = 0.0;
    for (int k = 0; k < kSamples; ++k) {
      const double v = 2.0 * kPi * k / kSamples;
      ca += g[k] * std::cos(h * v);
      sa += g[k] * std::sin(h * v);
    }
    arc_cos_[h] = (h == 0 ? 1.0 : 2.0) * ca / kSamples;
    arc_sin_[h] = 2.0 * sa / kSamples;
  }
  arc_sin_[0] = 0.0;
  arc_cos_[0] -= arcCorrection(0.0).v;  // u(0) = 0 exactly: the walk starts at the start
  // du/dv is about the mean speed over the curve's own: 0.15 along a stadium's sides.
  for (int k = 0; k < 1000; ++k) {
    if (1.0 + arcCorrection(2.0 * kPi * k / 1000).d < 0.1)
      throw std::logic_error("handheld motion: arc-length reparametrization is not monotonic");
  }
}

Jet HandheldMotion::arcCorrection(double v) const {
  Jet g{arc_cos_[0], 0.0, 0.0};
  const std::complex<double> step(std::cos(v), std::sin(v));
  std::complex<double> e = step;  // exp(i h v), by recurrence
  for (int h = 1; h <= arc_harmonics_; ++h, e *= step) {
    const double c = e.real(), s = e.imag();
    g.v += arc_cos_[h] * c + arc_sin_[h] * s;
    g.d += h * (-arc_cos_[h] * s + arc_sin_[h] * c);
    g.dd -= h * h * (arc_cos_[h] * c + arc_sin_[h] * s);
  }
  return g;
}

void HandheldMotion::curve(double u, Eigen::Vector2d* c, Eigen::Vector2d* dc,
                           Eigen::Vector2d* ddc) const {
  double x = 0, y = 0, dx = 0, dy = 0, ddx = 0, ddy = 0;
  double wiggle_x = rx_m_, wiggle_y = ry_m_;
  if (params_.loop_lobes <= 1) {
    x = rx_m_ * std::cos(u), y = ry_m_ * std::sin(u);
    dx = -rx_m_ * std::sin(u), dy = ry_m_ * std::cos(u);
    ddx = -rx_m_ * std::cos(u), ddy = -ry_m_ * std::sin(u);
    if (params_.loop_straightness > 0.0) {
      // A stadium: x = (Rx - Ry) S(u) + Ry cos u with S = tanh(k cos u) / tanh(k), which is 1
      // near u = 0 (the end is then the half circle of radius Ry around Rx - Ry) and sweeps to
      // -1 along the sides. An ellipse this thin turns on a radius of Ry^2 / Rx.
      const double k = params_.loop_straightness, T = std::tanh(k);
      const double w = k * std::cos(u), dw = -k * std::sin(u), ddw = -k * std::cos(u);
      const double th = std::tanh(w), sech2 = 1.0 - th * th;
      const double S = th / T, dS = sech2 * dw / T, ddS = sech2 * (ddw - 2.0 * th * dw * dw) / T;
      x = (rx_m_ - ry_m_) * S + ry_m_ * std::cos(u);
      dx = (rx_m_ - ry_m_) * dS - ry_m_ * std::sin(u);
      ddx = (rx_m_ - ry_m_) * ddS - ry_m_ * std::cos(u);
      // Wiggles along x of Rx's size would swing the ends back and forth faster than the walk
      // turns there (a 0.1 m radius at walking speed): along the straight sides they only vary
      // the pace, so they take the ends' size.
      wiggle_x = ry_m_;
    }
  } else {
    const double n = params_.loop_lobes, kappa = params_.loop_lobes % 2 == 1 ? 0.5 : 1.0;
    const double e = params_.lobe_size_variation, h = 0.5 * n;
    const double R = rx_m_ * (1.0 + e * std::cos(u + lobe_phase_));
    const double dR = -rx_m_ * e * std::sin(u + lobe_phase_);
    const double ddR = -rx_m_ * e * std::cos(u + lobe_phase_);
    const double sn = std::sin(h * u), cs = std::cos(h * u);
    const double rho = R * sn, drho = dR * sn + R * h * cs;
    const double ddrho = ddR * sn + 2.0 * dR * h * cs - R * h * h * sn;
    const double ct = std::cos(kappa * u), st = std::sin(kappa * u);
    // c = rho e + wiggles, e = (cos ku, sin ku), e' = k e_perp, e_perp' = -k e.
    x = rho * ct, y = rho * st;
    dx = drho * ct - rho * kappa * st, dy = drho * st + rho * kappa * ct;
    ddx = (ddrho - rho * kappa * kappa) * ct - 2.0 * drho * kappa * st;
    ddy = (ddrho - rho * kappa * kappa) * st + 2.0 * drho * kappa * ct;
    wiggle_x = wiggle_y = 0.25 * rx_m_;  // lobes pass near, not exactly through, the start
  }
  // Wiggles scale with each axis' radius so that thin loops (strip road) stay thin.
  for (int i = 0; i < 2; ++i) {
    const double k = i + 2;
    const double ax = a_[i] * wiggle_x, by = b_[i] * wiggle_y;
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

Jet HandheldMotion::phase(double t) const {
  const Jet tau = Jet{t, 1.0, 0.0} - pauses_.integral(t);  // walk clock
  const double m = speed_harmonic_, s = params_.speed_variation, w = omega_;
  const double arg = m * w * tau.v;
  const Jet v = chain(w * tau.v + (s / m) * std::sin(arg), w * (1.0 + s * std::cos(arg)),
                      -w * w * m * s * std::sin(arg), tau);
  const Jet g = arcCorrection(v.v);
  return chain(v.v + g.v, 1.0 + g.d, g.dd, v);
}

double HandheldMotion::baseYawRate(double t) const {
  const Jet u = phase(t);
  Eigen::Vector2d dc, ddc;
  curve(u.v, nullptr, &dc, &ddc);
  const double heading_rate = (dc.x() * ddc.y() - dc.y() * ddc.x()) / dc.squaredNorm() * u.d;
  return heading_rate + sineJet(params_.look_around_deg * kRadPerDeg, 0.11, phases_[3], t).d +
         sineJet(params_.look_around_fast_deg * kRadPerDeg, 0.43, phases_[4], t).d;
}

void HandheldMotion::drawFastTurns(double duration_s, std::uint64_t seed) {
  std::vector<Plateau> turns;
  if (params_.fast_turn_interval_s > 0.0) {
    Rng rng(streamSeed(seed, "motion-turns"));
    double t = 0.0;
    while (true) {
      Plateau p;
      p.t0_s = t + params_.fast_turn_interval_s * rng.uniform(0.5, 1.5);
      if (p.t0_s > duration_s + 60.0) break;
      p.weight = rng.uniform(params_.fast_turn_min_deg, params_.fast_turn_max_deg) * kRadPerDeg *
                 (rng.bernoulli(0.5) ? 1.0 : -1.0);
      p.hold_s = rng.uniform(0.3, 2.0);
      const double target = rng.uniform(0.75, 1.0) * params_.fast_turn_rate_deg_s * kRadPerDeg;
      // The peak of |base rate + turn rate| falls as the ramp lengthens: bisect the ramp time.
      auto peakRate = [&](double ramp_s) {
        Plateau q = p;
        q.ramp_s = ramp_s;
        double peak = 0.0;
        for (double s = q.t0_s; s <= q.end_s(); s += 0.02)
          peak = std::max(peak, std::abs(baseYawRate(s) + q.weight * q.value(s).d));
        return peak;
      };
      double lo = 0.3, hi = 8.0;
      for (int i = 0; i < 14; ++i) {
        const double mid = 0.5 * (lo + hi);
        (peakRate(mid) > target ? lo : hi) = mid;
      }
      p.ramp_s = hi;
      turns.push_back(p);
      t = p.end_s() + 1.0;
    }
  }
  turns_ = PlateauTrain(std::move(turns));
}

MotionState HandheldMotion::at(double t) const {
  const MotionParams& p = params_;
  const Jet u = phase(t);
  Eigen::Vector2d c, dc, ddc;
  curve(u.v, &c, &dc, &ddc);
  c -= offset_;
  const Jet path_x{c.x(), dc.x() * u.d, ddc.x() * u.d * u.d + dc.x() * u.dd};
  const Jet path_y{c.y(), dc.y() * u.d, ddc.y() * u.d * u.d + dc.y() * u.dd};

  // The gait fades while standing (walking share 1 -> 0): the stick sways a little still.
  const Jet walking = constant(1.0) - pauses_.value(t);
  const Jet sway_gain = constant(0.5) + 0.5 * walking;
  const Jet bob_gain = constant(0.25) + 0.75 * walking;
  const Jet tilt_gain = constant(0.4) + 0.6 * walking;
  const double f_step = p.step_frequency_hz;
  const Jet x = path_x + sway_gain * sineJet(p.sway_m, 0.5 * f_step, phases_[0], t);
  const Jet y = path_y + sway_gain * sineJet(p.sway_m, 0.37 * f_step, phases_[1], t);
  const Jet z = groundUnder(terrain_, path_x, path_y) + constant(p.sensor_height_m) +
                bob_gain * sineJet(p.bob_m, f_step, phases_[2], t);

  // Orientation: yaw follows the path heading plus look-around swings and fast turns; roll and
  // pitch sway with the gait.
  const double heading = std::atan2(dc.y(), dc.x());
  const double heading_rate = (dc.x() * ddc.y() - dc.y() * ddc.x()) / dc.squaredNorm() * u.d;
  const Jet yaw = Jet{heading, heading_rate, 0.0} +
                  sineJet(p.look_around_deg * kRadPerDeg, 0.11, phases_[3], t) +
                  sineJet(p.look_around_fast_deg * kRadPerDeg, 0.43, phases_[4], t) +
                  turns_.value(t);
  const Jet roll = tilt_gain * sineJet(p.roll_sway_deg * kRadPerDeg, 0.5 * f_step, phases_[5], t);
  const Jet pitch = constant(p.pitch_mean_deg * kRadPerDeg) +
                    tilt_gain * sineJet(p.pitch_sway_deg * kRadPerDeg, f_step, phases_[0] + 1.0, t);

  MotionState state;
  state.t_s = t;
  lie::SO3 R;
  eulerOrientation(roll, pitch, yaw, &R, &state.omega_body);
  state.T_world_body = lie::SE3(R, Eigen::Vector3d(x.v, y.v, z.v));
  state.v_world = Eigen::Vector3d(x.d, y.d, z.d);
  state.a_world = Eigen::Vector3d(x.dd, y.dd, z.dd);
  return state;
}

std::vector<Eigen::Vector2d> HandheldMotion::pathPolyline(double spacing_m) const {
  const int n = std::max(16, static_cast<int>(std::ceil(1.3 * length_m_ / spacing_m)));
  std::vector<Eigen::Vector2d> points;
  points.reserve(n);
  Eigen::Vector2d c;
  for (int i = 0; i < n; ++i) {
    const double v = 2.0 * kPi * i / n;  // equal arc length steps
    curve(v + arcCorrection(v).v, &c, nullptr, nullptr);
    points.push_back(c - offset_);
  }
  return points;
}
}  // namespace

std::unique_ptr<TrajectoryModel> makeHandheldMotion(const MotionParams& params, double duration_s,
                                                    std::uint64_t seed, Terrain terrain) {
  return std::make_unique<HandheldMotion>(params, duration_s, seed, std::move(terrain));
}

}  // namespace taiga::sim::detail
