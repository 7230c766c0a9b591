#include "taiga/trees/circle_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>
#include <vector>

#include "circle_coverage.hpp"
#include "taiga/trees/beam_circle_fit.hpp"

namespace taiga::trees {
namespace {

using Eigen::Vector2d;

// The circle through three points (the circumcircle), or nothing when they are collinear.
std::optional<Circle> circleThrough(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  const Vector2d ab = b - a, ac = c - a;
  const double d = 2.0 * (ab.x() * ac.y() - ab.y() * ac.x());
  if (std::abs(d) < 1e-12) return std::nullopt;
  const double ab2 = ab.squaredNorm(), ac2 = ac.squaredNorm();
  const Vector2d offset((ac.y() * ab2 - ab.y() * ac2) / d, (ab.x() * ac2 - ac.x() * ab2) / d);
  return Circle{a + offset, offset.norm()};
}

// RANSAC score: points on the ring, minus those well inside it. A stem is solid, so a large
// circle through branches and foliage around it (many points, many inside) loses to the stem's
// own ring. On squared distances (no square root): |d - r| < band is
// (r - band)^2 < d^2 < (r + band)^2 when r > band, d^2 < (r + band)^2 otherwise, and
// d - r < -2 band is d^2 < (r - 2 band)^2 when r > 2 band, never otherwise.
// Returns `beat` as soon as the score cannot exceed it (each remaining point adds at most 1): the
// caller keeps a circle only when it scores more than the best so far.
long ringScore(std::span<const Vector2d> points_m, const Circle& circle, double band_m, long beat) {
  const double r = circle.radius_m;
  const double on_lo2 = r > band_m ? (r - band_m) * (r - band_m) : -1.0;
  const double on_hi2 = (r + band_m) * (r + band_m);
  const double inside2 = r > 2.0 * band_m ? (r - 2.0 * band_m) * (r - 2.0 * band_m) : -1.0;
  const double cx = circle.center_m.x(), cy = circle.center_m.y();
  constexpr std::size_t kChunk = 32;
  long score = 0;
  for (std::size_t start = 0; start < points_m.size(); start += kChunk) {
    const std::size_t end = std::min(points_m.size(), start + kChunk);
    for (std::size_t i = start; i < end; ++i) {
      const double dx = points_m[i].x() - cx, dy = points_m[i].y() - cy;
      const double d2 = dx * dx + dy * dy;
      score += static_cast<long>(d2 > on_lo2 && d2 < on_hi2) - static_cast<long>(d2 < inside2);
    }
    if (score + static_cast<long>(points_m.size() - end) <= beat) return beat;
  }
  return score;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Tukey's biweight scale: 1.4826 MAD of the residuals near the circle, kept between a floor (a
// perfect arc must not give weight only to a handful of points) and the RANSAC band.
double robustScale(std::span<const Vector2d> points_m, const Circle& circle, double band_m) {
  std::vector<double> near;
  for (const Vector2d& p : points_m) {
    const double e = std::abs((p - circle.center_m).norm() - circle.radius_m);
    if (e < 3.0 * band_m) near.push_back(e);
  }
  return std::clamp(1.4826 * median(std::move(near)), 0.003, band_m);
}

// One point's residual across the surface, e = |p - c| - r, and its gradient in (cx, cy, r):
// de/dc = -(p - c) / |p - c|, de/dr = -1; nothing at the centre.
struct Residual {
  double e_m;
  Eigen::Vector3d J;
};
std::optional<Residual> residualOf(const Vector2d& p, const Circle& circle) {
  const Vector2d d = p - circle.center_m;
  const double distance = d.norm();
  if (!(distance > 1e-9)) return std::nullopt;
  return Residual{distance - circle.radius_m,
                  Eigen::Vector3d(-d.x() / distance, -d.y() / distance, -1.0)};
}

}  // namespace

double densestShare(std::span<const Vector2d> points_m, const std::vector<double>& weights,
                    const Vector2d& center_m) {
  std::array<int, 36> count{};
  int total = 0;
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    if (weights[i] <= 0.0) continue;
    const Vector2d d = points_m[i] - center_m;
    const double a = std::atan2(d.y(), d.x()) + std::numbers::pi;
    ++count[std::min<std::size_t>(35, static_cast<std::size_t>(a / (2.0 * std::numbers::pi) * 36))];
    ++total;
  }
  int best = 0;
  for (int k = 0; k < 36; ++k)
    best = std::max(best, count[k] + count[(k + 1) % 36] + count[(k + 2) % 36]);
  return total > 0 ? static_cast<double>(best) / total : 1.0;
}

double arcCoverageDeg(std::span<const Vector2d> points_m, const std::vector<double>& weights,
                      const Vector2d& center_m) {
  std::array<bool, 36> sector{};
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    if (weights[i] <= 0.0) continue;
    const Vector2d d = points_m[i] - center_m;
    const double a = std::atan2(d.y(), d.x()) + std::numbers::pi;  // 0 .. 2 pi
    sector[std::min<std::size_t>(35, static_cast<std::size_t>(a / (2.0 * std::numbers::pi) * 36))] =
        true;
  }
  return 10.0 * static_cast<double>(std::count(sector.begin(), sector.end(), true));
}

void describeFit(CircleFit& fit, std::span<const Vector2d> points_m,
                 const std::vector<double>& weights, const Eigen::Matrix3d& covariance) {
  fit.sigma_radius_m = std::sqrt(std::max(0.0, covariance(2, 2)));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> center(covariance.topLeftCorner<2, 2>());
  fit.sigma_center_m = std::sqrt(std::max(0.0, center.eigenvalues().maxCoeff()));
  fit.arc_deg = arcCoverageDeg(points_m, weights, fit.center_m);
  fit.densest_share = densestShare(points_m, weights, fit.center_m);
}

std::optional<CircleFit> refineCircle(std::span<const Vector2d> points_m, const Vector2d& center_m,
                                      double radius_m, const CircleFitOptions& options) {
  if (points_m.size() < 5) return std::nullopt;
  Circle circle{center_m, radius_m};
  const double scale_m = robustScale(points_m, circle, options.inlier_band_m);
  const double tukey_m = 4.685 * scale_m;
  std::vector<double> weights(points_m.size(), 0.0);
  Eigen::Matrix3d JtWJ;
  for (int iteration = 0; iteration < 30; ++iteration) {
    // Iteratively reweighted Gauss-Newton on the residuals (residualOf).
    JtWJ.setZero();
    Eigen::Vector3d JtWe = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < points_m.size(); ++i) {
      const std::optional<Residual> r = residualOf(points_m[i], circle);
      const double u = r ? r->e_m / tukey_m : 1.0;
      weights[i] = std::abs(u) < 1.0 ? (1 - u * u) * (1 - u * u) : 0.0;
      if (weights[i] == 0.0) continue;
      JtWJ += weights[i] * r->J * r->J.transpose();
      JtWe += weights[i] * r->J * r->e_m;
    }
    if (std::count_if(weights.begin(), weights.end(), [](double w) { return w > 0; }) < 5)
      return std::nullopt;
    const Eigen::Vector3d step = JtWJ.ldlt().solve(-JtWe);
    if (!step.allFinite()) return std::nullopt;
    circle.center_m += step.head<2>();
    circle.radius_m += step.z();
    if (step.norm() < 1e-7) break;
  }
  if (!(circle.radius_m >= options.min_radius_m && circle.radius_m <= options.max_radius_m))
    return std::nullopt;

  CircleFit fit;
  fit.center_m = circle.center_m;
  fit.radius_m = circle.radius_m;
  double weighted_sq = 0.0, weight_sum = 0.0, inlier_sq = 0.0;
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    if (weights[i] <= 0.0) continue;
    const std::optional<Residual> r = residualOf(points_m[i], circle);
    if (!r) {  // the point is at the centre
      weights[i] = 0.0;
      continue;
    }
    weighted_sq += weights[i] * r->e_m * r->e_m;
    weight_sum += weights[i];
    inlier_sq += r->e_m * r->e_m;
    ++fit.inliers;
  }
  if (fit.inliers == 0) return std::nullopt;
  fit.rms_m = std::sqrt(inlier_sq / static_cast<double>(fit.inliers));
  // Covariance of (cx, cy, r): sigma^2 (J^T W J)^-1 with sigma^2 the weighted residual variance.
  const double dof = std::max(1.0, weight_sum - 3.0);
  describeFit(fit, points_m, weights, (weighted_sq / dof) * JtWJ.inverse());
  return fit;
}

std::optional<CircleFit> fitStemSection(std::span<const Vector2d> points_m,
                                        const Vector2d& center_m, double radius_m,
                                        const CircleFitOptions& options,
                                        std::span<const Vector2d> beams) {
  const std::optional<CircleFit> across = refineCircle(points_m, center_m, radius_m, options);
  if (!across || beams.empty()) return across;
  // The range noise from the scatter across the surface (for a ring of points it is the range
  // noise), kept within what lidars have: 1 cm to 5 cm.
  const double range_sigma_m = std::clamp(across->rms_m, 0.01, 0.05);
  const std::optional<CircleFit> along =
      fitCircleAlongBeams(points_m, beams, center_m, radius_m, range_sigma_m, options);
  if (!along || along->arc_deg < 0.6 * across->arc_deg) return across;
  return along;
}

namespace {

// Each point's block for the jackknife: the points sorted by the direction they were seen from
// (their beam's azimuth; where the beam is unknown, their azimuth around the centre), starting
// after the widest gap between directions, cut into `blocks` runs of about equal count, each cut
// moved to the widest gap within half a block of its place. Points of one keyframe share a
// direction, so a block holds whole views (a block that splits a view keeps its placement).
std::vector<int> viewBlocks(std::span<const Vector2d> points_m, std::span<const Vector2d> beams,
                            const Vector2d& center_m, int blocks) {
  const std::size_t n = points_m.size();
  std::vector<double> azimuth(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool known = i < beams.size() && beams[i].squaredNorm() > 0.0;
    const Vector2d d = known ? beams[i] : Vector2d(points_m[i] - center_m);
    azimuth[i] = std::atan2(d.y(), d.x());
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return azimuth[a] < azimuth[b]; });
  std::size_t first = 0;  // the run starts after the widest gap (circularly)
  double widest = azimuth[order[0]] + 2.0 * std::numbers::pi - azimuth[order[n - 1]];
  for (std::size_t k = 1; k < n; ++k)
    if (azimuth[order[k]] - azimuth[order[k - 1]] > widest) {
      widest = azimuth[order[k]] - azimuth[order[k - 1]];
      first = k;
    }
  auto gapBefore = [&](std::size_t k) {  // k-th in the run, 1 .. n-1
    const double a = azimuth[order[(first + k) % n]], b = azimuth[order[(first + k - 1) % n]];
    return a >= b ? a - b : a + 2.0 * std::numbers::pi - b;
  };
  std::vector<std::size_t> cuts{0};
  const std::size_t half = std::max<std::size_t>(1, n / (2 * static_cast<std::size_t>(blocks)));
  for (int c = 1; c < blocks; ++c) {
    const std::size_t at = static_cast<std::size_t>(c) * n / static_cast<std::size_t>(blocks);
    std::size_t best = at;
    for (std::size_t k = std::max(cuts.back() + 1, at - std::min(at, half));
         k <= std::min(n - 1, at + half); ++k)
      if (gapBefore(k) > gapBefore(best)) best = k;
    cuts.push_back(std::max(best, cuts.back() + 1));
  }
  cuts.push_back(n);
  std::vector<int> block(n);
  for (int c = 0; c < blocks; ++c)
    for (std::size_t k = cuts[static_cast<std::size_t>(c)];
         k < std::min(n, cuts[static_cast<std::size_t>(c) + 1]); ++k)
      block[order[(first + k) % n]] = c;
  return block;
}

}  // namespace

double viewJackknifeSigmaRadius(std::span<const Vector2d> points_m, std::span<const Vector2d> beams,
                                const CircleFit& fit, const Vector2d& start_center_m,
                                double start_radius_m, const CircleFitOptions& options) {
  constexpr int kBlocks = 8;
  if (points_m.size() < 2 * kBlocks) return 0.0;
  const std::vector<int> block = viewBlocks(points_m, beams, fit.center_m, kBlocks);
  std::vector<double> radii_m;
  std::vector<Vector2d> kept_points, kept_beams;
  for (int left_out = 0; left_out < kBlocks; ++left_out) {
    kept_points.clear();
    kept_beams.clear();
    for (std::size_t i = 0; i < points_m.size(); ++i) {
      if (block[i] == left_out) continue;
      kept_points.push_back(points_m[i]);
      if (!beams.empty()) kept_beams.push_back(beams[i]);
    }
    const std::optional<CircleFit> refit =
        fitStemSection(kept_points, start_center_m, start_radius_m, options, kept_beams);
    if (refit) radii_m.push_back(refit->radius_m);
  }
  if (radii_m.size() < 3) return 0.0;
  // Delete-one-block jackknife: sqrt((g-1)/g sum (r_k - mean)^2) over the g refits.
  const auto g = static_cast<double>(radii_m.size());
  double mean_m = 0.0;
  for (const double r : radii_m) mean_m += r / g;
  double sum_sq = 0.0;
  for (const double r : radii_m) sum_sq += (r - mean_m) * (r - mean_m);
  return std::sqrt((g - 1.0) / g * sum_sq);
}

std::optional<CircleFit> fitCircleRobust(std::span<const Vector2d> points_m,
                                         const CircleFitOptions& options) {
  const std::size_t n = points_m.size();
  if (n < 5) return std::nullopt;
  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  // Scored on at most 400 points: enough to rank circles, and the cost stays flat for big
  // clusters (a crowded cluster needs many draws: with 20 % of its points on the stem, 1000 draws
  // find three of them with 99.97 % probability).
  std::vector<Vector2d> sample(points_m.begin(), points_m.end());
  if (sample.size() > 400) {
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(400);
  }
  std::optional<Circle> best;
  long best_score = 0;
  for (int iteration = 0; iteration < options.ransac_iterations; ++iteration) {
    const std::size_t i = pick(rng), j = pick(rng), k = pick(rng);
    if (i == j || j == k || i == k) continue;
    const std::optional<Circle> circle = circleThrough(points_m[i], points_m[j], points_m[k]);
    if (!circle || circle->radius_m < options.min_radius_m ||
        circle->radius_m > options.max_radius_m)
      continue;
    const long score = ringScore(sample, *circle, options.inlier_band_m, best_score);
    if (score > best_score) {
      best_score = score;
      best = circle;
    }
  }
  if (!best || best_score < 5) return std::nullopt;
  return refineCircle(points_m, best->center_m, best->radius_m, options);
}

}  // namespace taiga::trees
