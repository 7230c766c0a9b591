#include "taiga/georef/als_registration.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "taiga/core/log.hpp"
#include "taiga/registration/correlative_search.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/kdtree.hpp"
#include "taiga/registration/result.hpp"

namespace taiga::georef {
namespace {

using Vec3 = Eigen::Vector3d;

constexpr double kThin_m = 0.3;        ///< the map is thinned to one point per voxel this size
constexpr double kGroundCell_m = 1.0;  ///< the map's lowest point per cell: its ground
constexpr double kGroundBand_m = 0.3;  ///< ground: within this of the cell's lowest point
constexpr double kCrownAbove_m = 3.0;  ///< crowns: more than this above it
constexpr double kHeightCell_m = 2.0;  ///< cells of the height step
constexpr double kNear_m = 1.0;        ///< coverage: an ALS point within this
constexpr std::size_t kMaxGicpSource = 100000;
/// A search candidate farther than this from the best is in another basin (an alternative).
constexpr double kOtherBasin_m = 4.0, kOtherBasin_deg = 4.0;

std::uint64_t key2(double x, double y, double cell) {
  const auto i = static_cast<std::int64_t>(std::floor(x / cell)) + (1ll << 31);
  const auto j = static_cast<std::int64_t>(std::floor(y / cell)) + (1ll << 31);
  return static_cast<std::uint64_t>(i) << 32 | static_cast<std::uint64_t>(j);
}

std::uint64_t key3(const Vec3& p, double voxel) {
  const auto q = (p / voxel).array().floor().cast<std::int64_t>() + (1ll << 20);
  return static_cast<std::uint64_t>(q.x()) << 42 | static_cast<std::uint64_t>(q.y()) << 21 |
         static_cast<std::uint64_t>(q.z());
}

/// One point per voxel, the first.
std::vector<Vec3> thin(std::span<const Vec3> points, double voxel_m) {
  std::unordered_set<std::uint64_t> taken;
  std::vector<Vec3> out;
  for (const Vec3& p : points)
    if (p.allFinite() && taken.insert(key3(p, voxel_m)).second) out.push_back(p);
  return out;
}

std::unordered_map<std::uint64_t, double> lowestPerCell(std::span<const Vec3> points,
                                                        double cell_m) {
  std::unordered_map<std::uint64_t, double> lowest;
  for (const Vec3& p : points) {
    const auto [it, fresh] = lowest.try_emplace(key2(p.x(), p.y(), cell_m), p.z());
    if (!fresh) it->second = std::min(it->second, p.z());
  }
  return lowest;
}

/// Step 1: the map's ground and crown points, thinned (map frame).
std::vector<Vec3> groundAndCrowns(std::span<const Vec3> map_points) {
  const std::vector<Vec3> thinned = thin(map_points, kThin_m);
  const auto lowest = lowestPerCell(thinned, kGroundCell_m);
  std::vector<Vec3> out;
  for (const Vec3& p : thinned) {
    const double above_m = p.z() - lowest.at(key2(p.x(), p.y(), kGroundCell_m));
    if (above_m < kGroundBand_m || above_m > kCrownAbove_m) out.push_back(p);
  }
  return out;
}

/// Step 2: how much higher the ALS's lowest points lie than the map's, the median over the cells
/// both have; none without a common cell.
std::optional<double> heightShift(std::span<const Vec3> map_local,
                                  std::span<const Vec3> als_local) {
  const auto map_lowest = lowestPerCell(map_local, kHeightCell_m);
  const auto als_lowest = lowestPerCell(als_local, kHeightCell_m);
  std::vector<double> differences;
  for (const auto& [cell, z] : map_lowest) {
    const auto it = als_lowest.find(cell);
    if (it != als_lowest.end()) differences.push_back(it->second - z);
  }
  if (differences.empty()) return std::nullopt;
  auto middle = differences.begin() + static_cast<std::ptrdiff_t>(differences.size() / 2);
  std::nth_element(differences.begin(), middle, differences.end());
  return *middle;
}

std::vector<Vec3> transformed(std::span<const Vec3> points, const lie::SE3& T) {
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Vec3& p : points) out.push_back(T * p);
  return out;
}

lie::SE3 raised(const lie::SE3& T, double dz_m) {
  return lie::SE3(T.rotation(), T.translation() + Vec3(0.0, 0.0, dz_m));
}

/// An even subsample of at most n points.
std::vector<Vec3> subsample(std::span<const Vec3> points, std::size_t n) {
  const std::size_t step = points.size() / n + 1;
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < points.size(); i += step) out.push_back(points[i]);
  return out;
}

/// 1-sigma in the grid's axes (east, north, up; roll, pitch, yaw) by a delete-a-group jackknife:
/// the map's four quadrants left out in turn, each remainder registered again from the solution;
/// variance = (g - 1) / g * sum of the squared deviations from their mean (Efron & Stein). The
/// points' errors are not independent (the viewpoints shape the crowns the map and the aircraft
/// see alike over metres), so the GICP Hessian's formal covariance is millimetres where the error
/// is centimetres; whole quadrants carry that correlation.
Eigen::Matrix<double, 6, 1> jackknifeSigma(std::span<const Vec3> source,
                                           std::span<const Vec3> als_local,
                                           const lie::SE3& solution,
                                           const registration::GicpConfig& gicp) {
  std::vector<double> xs, ys;
  for (const Vec3& p : source) {
    xs.push_back(p.x());
    ys.push_back(p.y());
  }
  std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
  std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
  const double x_mid = xs[xs.size() / 2], y_mid = ys[ys.size() / 2];
  constexpr int kGroups = 4;
  std::vector<lie::Vector6> deviations;
  for (int left_out = 0; left_out < kGroups; ++left_out) {
    std::vector<Vec3> kept;
    for (const Vec3& p : source)
      if ((p.x() >= x_mid ? 1 : 0) + (p.y() >= y_mid ? 2 : 0) != left_out) kept.push_back(p);
    const registration::RegistrationResult r =
        registration::alignGicp(kept, als_local, solution, gicp);
    // The deviation in the grid's axes: translation, and the rotation vector R theta.
    const lie::Vector6 d = r.T_target_source.minus(solution);
    lie::Vector6 grid;
    grid.head<3>() = r.T_target_source.translation() - solution.translation();
    grid.tail<3>() = solution.rotation().matrix() * d.tail<3>();
    deviations.push_back(grid);
  }
  lie::Vector6 mean = lie::Vector6::Zero();
  for (const lie::Vector6& d : deviations) mean += d / kGroups;
  lie::Vector6 variance = lie::Vector6::Zero();
  for (const lie::Vector6& d : deviations) variance += (d - mean).cwiseAbs2();
  return (variance * (kGroups - 1.0) / kGroups).cwiseSqrt();
}

AlsRegistration failed(AlsRegistration r, std::string reason) {
  r.ok = false;
  r.reason = std::move(reason);
  return r;
}

/// Step 3's outcome.
struct Search {
  lie::SE3 T_local_map;  ///< the fine search's best pose
  double score = 0.0;    ///< its score
  double best_coarse_score = 0.0;
  /// The best coarse candidate in another basin (the search's distinct candidates include the
  /// best one's neighbours 2 m or 2 deg away), if any.
  std::optional<registration::CorrelativeCandidate> alternative;
  registration::Separation alternative_apart;
};

Search searchHeadingAndPosition(std::span<const Vec3> selected, std::span<const Vec3> als_local,
                                const lie::SE3& T_local_map,
                                const AlsRegistrationOptions& options) {
  const registration::Occupancy coarse(als_local, 2.0);
  const std::vector<registration::CorrelativeCandidate> candidates =
      registration::correlativeSearch(selected, coarse, T_local_map,
                                      {.yaw_half_deg = options.search_yaw_deg,
                                       .yaw_step_deg = 1.0,
                                       .xy_half_m = options.search_xy_m,
                                       .xy_step_m = 1.0,
                                       .voxel_m = 2.0,
                                       .max_source = 3000},
                                      12);
  Search search;
  if (candidates.empty()) return search;
  const lie::SE3& best = candidates.front().T_target_source;
  search.best_coarse_score = candidates.front().score;
  for (const auto& c : candidates) {
    logger().debug("ALS coarse candidate: {:.2f} m, {:.2f} deg from the start, score {:.3f}",
                   (c.T_target_source.translation() - T_local_map.translation()).norm(),
                   registration::separation(T_local_map, c.T_target_source).deg, c.score);
    const registration::Separation apart = registration::separation(best, c.T_target_source);
    if (!search.alternative && (apart.m > kOtherBasin_m || apart.deg > kOtherBasin_deg)) {
      search.alternative = c;
      search.alternative_apart = apart;
    }
  }
  const registration::Occupancy fine(als_local, 1.0);
  const registration::CorrelativeCandidate refined =
      registration::correlativeSearch(selected, fine, best,
                                      {.yaw_half_deg = 1.5,
                                       .yaw_step_deg = 0.25,
                                       .xy_half_m = 1.5,
                                       .xy_step_m = 0.25,
                                       .voxel_m = 1.0,
                                       .max_source = 3000},
                                      1)
          .front();
  search.T_local_map = refined.T_target_source;
  search.score = refined.score;
  return search;
}

/// Step 4: GICP from the search's pose, wide correspondences first (their cost is smoother, so
/// starts a few decimetres and tenths of a degree apart settle in one place), then kNear_m.
registration::RegistrationResult alignSixDof(std::span<const Vec3> source,
                                             std::span<const Vec3> als_local, lie::SE3 T_local_map,
                                             const registration::GicpConfig& gicp) {
  registration::GicpConfig wide = gicp;
  wide.max_correspondence_distance_m = 2.5 * kNear_m;
  const registration::RegistrationResult settled =
      registration::alignGicp(source, als_local, T_local_map, wide);
  if (settled.converged) T_local_map = settled.T_target_source;
  registration::RegistrationResult r =
      registration::alignGicp(source, als_local, T_local_map, gicp);
  if (!r.converged && r.reason.starts_with("no convergence")) {
    // The correspondences within kNear_m can switch back and forth near the solution, and the
    // steps never fall below GICP's 0.1 mm: a second run from where the first stopped that moves
    // less than 2 cm and 0.02 deg says the pose is settled to that.
    registration::RegistrationResult again =
        registration::alignGicp(source, als_local, r.T_target_source, gicp);
    const registration::Separation moved =
        registration::separation(r.T_target_source, again.T_target_source);
    if (moved.m < 0.02 && moved.deg < 0.02) {
      again.converged = true;
      again.reason.clear();
    }
    r = std::move(again);
  }
  logger().debug("ALS GICP: {} iterations, {:.3f} m and {:.3f} deg from the search, {}",
                 r.iterations, (r.T_target_source.translation() - T_local_map.translation()).norm(),
                 registration::separation(T_local_map, r.T_target_source).deg, r.reason);
  return r;
}

/// Step 5's coverage: the share of `source` (placed by T) with an ALS point within kNear_m.
double coverage(std::span<const Vec3> source, std::span<const Vec3> als_local,
                const lie::SE3& T_local_map) {
  const registration::KdTree als_tree(als_local);
  std::size_t near = 0;
  for (const Vec3& p : source) {
    std::size_t index = 0;
    double d2 = 0.0;
    near += als_tree.nearestWithin(T_local_map * p, kNear_m, index, d2);
  }
  return static_cast<double>(near) / static_cast<double>(std::max<std::size_t>(source.size(), 1));
}

}  // namespace

AlsRegistration registerToAls(std::span<const Vec3> map_points, std::span<const Vec3> als_points,
                              const lie::SE3& guess, const AlsRegistrationOptions& options) {
  AlsRegistration result;
  // A local grid frame near the map: the grid's millions of metres would cost float precision
  // in the search structures.
  const Vec3 origin = guess.translation().array().round();
  std::vector<Vec3> als_local;
  als_local.reserve(als_points.size());
  for (const Vec3& p : als_points)
    if (p.allFinite()) als_local.push_back(p - origin);
  result.als_points = als_local.size();
  const std::vector<Vec3> selected = groundAndCrowns(map_points);
  result.map_points = selected.size();
  if (selected.size() < 500)
    return failed(result,
                  fmt::format("the map has {} ground and crown points (at least 500 needed)",
                              selected.size()));
  if (als_local.size() < 500)
    return failed(result, fmt::format("{} ALS points (at least 500 needed)", als_local.size()));

  // Step 2: the height.
  lie::SE3 T_local_map(guess.rotation(), guess.translation() - origin);
  const std::optional<double> dz = heightShift(transformed(selected, T_local_map), als_local);
  if (!dz)
    return failed(result,
                  "the ALS does not cover the map: no 2 m cell in common at the guessed position");
  T_local_map = raised(T_local_map, *dz);

  // Step 3: heading and position; the height again.
  const Search search = searchHeadingAndPosition(selected, als_local, T_local_map, options);
  if (search.best_coarse_score <= 0.0)
    return failed(result, "the correlative search found no candidate");
  result.score = search.score;
  if (search.alternative)
    result.second_score = search.alternative->score / search.best_coarse_score * search.score;
  T_local_map = search.T_local_map;
  if (const auto again = heightShift(transformed(selected, T_local_map), als_local))
    T_local_map = raised(T_local_map, *again);
  result.height_shift_m = T_local_map.translation().z() + origin.z() - guess.translation().z();

  // Step 4: six degrees of freedom.
  const std::vector<Vec3> source = subsample(selected, kMaxGicpSource);
  registration::GicpConfig gicp;
  gicp.max_correspondence_distance_m = kNear_m;
  gicp.max_iterations = 200;  // from a search 0.25 m / 0.25 deg apart: more steps than the odometry
  const registration::RegistrationResult r = alignSixDof(source, als_local, T_local_map, gicp);
  if (!r.converged) return failed(result, "GICP to the ALS did not converge: " + r.reason);
  T_local_map = r.T_target_source;
  result.T_grid_map = lie::SE3(T_local_map.rotation(), T_local_map.translation() + origin);

  // Step 5: checks, then the 1-sigma.
  result.coverage = coverage(source, als_local, T_local_map);
  if (result.coverage < options.min_coverage)
    return failed(result, fmt::format("the ALS covers {:.0f} % of the map's ground and crowns "
                                      "(at least {:.0f} % needed): another tile, or a wrong guess",
                                      100.0 * result.coverage, 100.0 * options.min_coverage));
  if (search.alternative &&
      search.alternative->score > options.max_second_score * search.best_coarse_score)
    return failed(result, fmt::format("ambiguous: a pose {:.1f} m / {:.1f} deg from the best "
                                      "scores {:.3f} against {:.3f}",
                                      search.alternative_apart.m, search.alternative_apart.deg,
                                      search.alternative->score, search.best_coarse_score));
  result.sigma = jackknifeSigma(source, als_local, T_local_map, gicp);
  result.ok = true;
  return result;
}

}  // namespace taiga::georef
