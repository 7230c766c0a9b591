#pragma once
// Building blocks of the analytic trajectories: a value with its first two time derivatives
// (a second-order jet, propagated by the chain and product rules), sines, and smooth plateaus
// (0 -> 1 -> 0 with quintic "smootherstep" ramps, C2 everywhere) with their exact integrals.
// Sums of plateaus make the pauses of a walk and the drives of a harvester: a speed profile that
// goes smoothly to zero and back, whose integral (the distance) is a polynomial in closed form.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace taiga::sim::detail {

/// f(t), f'(t), f''(t).
struct Jet {
  double v = 0.0, d = 0.0, dd = 0.0;
};

inline Jet constant(double value) { return {value, 0.0, 0.0}; }
inline Jet operator+(const Jet& a, const Jet& b) { return {a.v + b.v, a.d + b.d, a.dd + b.dd}; }
inline Jet operator-(const Jet& a, const Jet& b) { return {a.v - b.v, a.d - b.d, a.dd - b.dd}; }
inline Jet operator-(const Jet& a) { return {-a.v, -a.d, -a.dd}; }
inline Jet operator*(double s, const Jet& a) { return {s * a.v, s * a.d, s * a.dd}; }
/// (ab)'' = a''b + 2a'b' + ab''.
inline Jet operator*(const Jet& a, const Jet& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd};
}
/// f(x(t)) from f, f', f'' at x: (f o x)'' = f''(x) x'^2 + f'(x) x''.
inline Jet chain(double f, double df, double ddf, const Jet& x) {
  return {f, df * x.d, ddf * x.d * x.d + df * x.dd};
}
inline Jet sin(const Jet& x) {
  const double s = std::sin(x.v), c = std::cos(x.v);
  return chain(s, c, -s, x);
}
inline Jet cos(const Jet& x) {
  const double s = std::sin(x.v), c = std::cos(x.v);
  return chain(c, -s, -c, x);
}
inline Jet atan(const Jet& x) {
  const double q = 1.0 / (1.0 + x.v * x.v);
  return chain(std::atan(x.v), q, -2.0 * x.v * q * q, x);
}

/// A sin(2 pi f t + phase).
inline Jet sineJet(double amplitude, double frequency_hz, double phase, double t) {
  const double w = 2.0 * std::numbers::pi * frequency_hz;
  const double s = std::sin(w * t + phase), c = std::cos(w * t + phase);
  return {amplitude * s, amplitude * w * c, -amplitude * w * w * s};
}

/// Quintic smootherstep S(x) = 6x^5 - 15x^4 + 10x^3 on [0, 1] (S', S'' vanish at both ends),
/// its derivatives and its integral from 0.
struct Smootherstep {
  double value, d1, d2, integral;
};
inline Smootherstep smootherstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  const double x2 = x * x, x3 = x2 * x;
  return {x3 * (10.0 + x * (-15.0 + 6.0 * x)), 30.0 * x2 * (1.0 - x) * (1.0 - x),
          60.0 * x * (1.0 - x) * (1.0 - 2.0 * x), x3 * x * (2.5 + x * (-3.0 + x))};
}

/// 0 before t0, a smootherstep up over `ramp_s`, 1 for `hold_s`, a smootherstep down over
/// `ramp_s`, 0 after. Area = ramp_s + hold_s.
struct Plateau {
  double t0_s = 0.0;
  double ramp_s = 1.0;
  double hold_s = 0.0;
  double weight = 1.0;  ///< the plateau's height (e.g. a speed)

  double end_s() const { return t0_s + 2.0 * ramp_s + hold_s; }
  double holdStart_s() const { return t0_s + ramp_s; }
  double holdEnd_s() const { return t0_s + ramp_s + hold_s; }
  double area() const { return ramp_s + hold_s; }

  /// Unit-height value and derivatives at t.
  Jet value(double t) const {
    if (t <= t0_s || t >= end_s()) return {};
    if (t < holdStart_s()) {
      const Smootherstep s = smootherstep((t - t0_s) / ramp_s);
      return {s.value, s.d1 / ramp_s, s.d2 / (ramp_s * ramp_s)};
    }
    if (t <= holdEnd_s()) return {1.0, 0.0, 0.0};
    const Smootherstep s = smootherstep((t - holdEnd_s()) / ramp_s);
    return {1.0 - s.value, -s.d1 / ramp_s, -s.d2 / (ramp_s * ramp_s)};
  }
  /// Unit-height integral from -infinity to t, with its derivatives (the value and its slope).
  Jet integral(double t) const {
    const Jet p = value(t);
    double i = 0.0;
    if (t <= t0_s) {
      i = 0.0;
    } else if (t < holdStart_s()) {
      i = ramp_s * smootherstep((t - t0_s) / ramp_s).integral;
    } else if (t <= holdEnd_s()) {
      i = 0.5 * ramp_s + (t - holdStart_s());
    } else if (t < end_s()) {
      const double x = (t - holdEnd_s()) / ramp_s;  // integral of 1 - S over [0, x]
      i = 0.5 * ramp_s + hold_s + ramp_s * (x - smootherstep(x).integral);
    } else {
      i = area();
    }
    return {i, p.v, p.d};
  }
};

/// Non-overlapping plateaus in time order: sum_i weight_i P_i(t) and its integral.
class PlateauTrain {
 public:
  PlateauTrain() = default;
  explicit PlateauTrain(std::vector<Plateau> plateaus) : plateaus_(std::move(plateaus)) {
    std::sort(plateaus_.begin(), plateaus_.end(),
              [](const Plateau& a, const Plateau& b) { return a.t0_s < b.t0_s; });
    prefix_.clear();
    double sum = 0.0;
    for (const Plateau& p : plateaus_) {
      prefix_.push_back(sum);
      sum += p.weight * p.area();
    }
    prefix_.push_back(sum);
  }

  const std::vector<Plateau>& plateaus() const { return plateaus_; }

  /// sum_i w_i P_i(t) with derivatives (at most one plateau is active at a time).
  Jet value(double t) const {
    const std::size_t i = active(t);
    return i < plateaus_.size() ? plateaus_[i].weight * plateaus_[i].value(t) : Jet{};
  }
  /// integral of the sum from -infinity to t, with derivatives.
  Jet integral(double t) const {
    const std::size_t i = active(t);
    if (i >= plateaus_.size()) return {prefix_[ended(t)], 0.0, 0.0};
    return constant(prefix_[i]) + plateaus_[i].weight * plateaus_[i].integral(t);
  }

 private:
  /// Number of plateaus that ended at or before t.
  std::size_t ended(double t) const {
    return static_cast<std::size_t>(
        std::upper_bound(plateaus_.begin(), plateaus_.end(), t,
                         [](double time, const Plateau& p) { return time < p.end_s(); }) -
        plateaus_.begin());
  }
  /// Index of the plateau whose support contains t, or plateaus_.size().
  std::size_t active(double t) const {
    const std::size_t i = ended(t);
    return i < plateaus_.size() && t > plateaus_[i].t0_s ? i : plateaus_.size();
  }

  std::vector<Plateau> plateaus_;
  std::vector<double> prefix_{0.0};  ///< integral of all plateaus before index i
};

}  // namespace taiga::sim::detail
