#pragma once
// Helpers for testing Lie-group code: random elements, edge-case tangents and numerical
// (central-difference) Jacobians on manifolds, using the right plus/minus of lie/so3.hpp.

#include <Eigen/Core>
#include <numbers>
#include <random>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/lie/so3.hpp"

namespace taiga::test {

/// Manifold traits: dimension, right plus and right minus. Vectors are manifolds too.
template <class T>
struct Manifold;

template <int N>
struct Manifold<Eigen::Matrix<double, N, 1>> {
  using Element = Eigen::Matrix<double, N, 1>;
  using Tangent = Element;
  static constexpr int kDim = N;
  static Element plus(const Element& x, const Tangent& d) { return x + d; }
  static Tangent minus(const Element& y, const Element& x) { return y - x; }
};

template <>
struct Manifold<lie::SO3> {
  using Tangent = lie::Vector3;
  static constexpr int kDim = 3;
  static lie::SO3 plus(const lie::SO3& x, const Tangent& d) { return x.plus(d); }
  static Tangent minus(const lie::SO3& y, const lie::SO3& x) { return y.minus(x); }
};

template <>
struct Manifold<lie::SE3> {
  using Tangent = lie::Vector6;
  static constexpr int kDim = 6;
  static lie::SE3 plus(const lie::SE3& x, const Tangent& d) { return x.plus(d); }
  static Tangent minus(const lie::SE3& y, const lie::SE3& x) { return y.minus(x); }
};

/// J = d f(x (+) d) (-) f(x) / d d at d = 0, by central differences.
template <class In, class F>
auto numericalJacobian(F f, const In& x, double step = 1e-6) {
  using Out = decltype(f(x));
  using MIn = Manifold<In>;
  using MOut = Manifold<Out>;
  Eigen::Matrix<double, MOut::kDim, MIn::kDim> J;
  const Out y0 = f(x);
  for (int i = 0; i < MIn::kDim; ++i) {
    typename MIn::Tangent d = MIn::Tangent::Zero();
    d[i] = step;
    const auto forward = MOut::minus(f(MIn::plus(x, d)), y0);
    const auto backward = MOut::minus(f(MIn::plus(x, -d)), y0);
    J.col(i) = (forward - backward) / (2.0 * step);
  }
  return J;
}

/// Rotation angles where closed forms are fragile: zero, tiny, around the series threshold,
/// moderate, and close to pi.
inline std::vector<double> edgeCaseAngles() {
  const double pi = std::numbers::pi;
  return {0.0, 1e-12, 1e-8, 1e-5, 0.0099999, 0.0100001, 0.3, 1.0, 2.5, pi - 1e-3, pi - 1e-6};
}

class RandomLie {
 public:
  explicit RandomLie(unsigned seed) : rng_(seed) {}
  lie::Vector3 unitVector() {
    lie::Vector3 v;
    do v = lie::Vector3(normal_(rng_), normal_(rng_), normal_(rng_));
    while (v.norm() < 1e-3);
    return v.normalized();
  }
  /// A rotation vector with angle uniform in [0, max_angle).
  lie::Vector3 rotationVector(double max_angle = std::numbers::pi) {
    return unitVector() * std::uniform_real_distribution<double>(0.0, max_angle)(rng_);
  }
  lie::Vector3 translation(double scale = 5.0) {
    return scale * lie::Vector3(normal_(rng_), normal_(rng_), normal_(rng_));
  }
  lie::SO3 so3() { return lie::SO3::Exp(rotationVector()); }
  lie::SE3 se3() { return lie::SE3(so3(), translation()); }
  lie::Vector6 se3Tangent(double max_angle = std::numbers::pi) {
    return lie::makeTangent(translation(), rotationVector(max_angle));
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> normal_;
};

}  // namespace taiga::test
