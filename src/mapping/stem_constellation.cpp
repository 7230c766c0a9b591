#include "taiga/mapping/stem_constellation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

#include "taiga/trees/inventory.hpp"

namespace taiga::mapping {
namespace {

struct Pair {
  double distance_m;
  std::size_t a, b;
};

std::vector<Pair> pairsOf(std::span<const StemMark> marks, const ConstellationOptions& options) {
  std::vector<Pair> pairs;
  for (std::size_t a = 0; a < marks.size(); ++a)
    for (std::size_t b = a + 1; b < marks.size(); ++b) {
      const double d_m = (marks[a].position_m.head<2>() - marks[b].position_m.head<2>()).norm();
      if (d_m >= options.min_pair_m && d_m <= options.max_pair_m) pairs.push_back({d_m, a, b});
    }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) {
    return std::tie(x.distance_m, x.a, x.b) < std::tie(y.distance_m, y.a, y.b);
  });
  return pairs;
}

bool sameDbh(const StemMark& x, const StemMark& y, const ConstellationOptions& options) {
  return std::abs(x.dbh_m - y.dbh_m) <=
         std::max(0.03, options.dbh_tolerance * std::max(x.dbh_m, y.dbh_m));
}

/// A horizontal rigid motion p_target = R(yaw) p_source + t.
struct Motion2 {
  double yaw_rad = 0.0;
  Eigen::Vector2d t_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    return Eigen::Rotation2Dd(yaw_rad) * p + t_m;
  }
};

/// The target stems hashed on an inlier_m grid: a hypothesis is scored by looking up each source
/// stem's 3 x 3 cells, not every target stem (tens of thousands of hypotheses).
class TargetGrid {
 public:
  TargetGrid(std::span<const StemMark> target, double cell_m) : target_(target), cell_m_(cell_m) {
    for (std::size_t a = 0; a < target.size(); ++a)
      cells_[key(target[a].position_m.head<2>())].push_back(a);
  }

  /// The nearest target stem of similar DBH within inlier_m, or target.size().
  std::size_t nearest(const StemMark& mark, const Eigen::Vector2d& p,
                      const ConstellationOptions& options) const {
    const auto [cx, cy] = key(p);
    double best_m = options.inlier_m;
    std::size_t best = target_.size();
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        const auto cell = cells_.find({cx + dx, cy + dy});
        if (cell == cells_.end()) continue;
        for (const std::size_t a : cell->second) {
          const double d_m = (target_[a].position_m.head<2>() - p).norm();
          if (d_m < best_m && sameDbh(mark, target_[a], options)) {
            best_m = d_m;
            best = a;
          }
        }
      }
    return best;
  }

 private:
  std::pair<long, long> key(const Eigen::Vector2d& p) const {
    return {static_cast<long>(std::floor(p.x() / cell_m_)),
            static_cast<long>(std::floor(p.y() / cell_m_))};
  }
  std::span<const StemMark> target_;
  double cell_m_;
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells_;
};

/// Each source stem's nearest target stem of similar DBH within inlier_m.
std::vector<std::pair<std::size_t, std::size_t>> inliersOf(const Motion2& motion,
                                                           std::span<const StemMark> source,
                                                           const TargetGrid& grid,
                                                           std::size_t target_size,
                                                           const ConstellationOptions& options) {
  std::vector<std::pair<std::size_t, std::size_t>> matched;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const std::size_t a =
        grid.nearest(source[i], motion.apply(source[i].position_m.head<2>()), options);
    if (a < target_size) matched.emplace_back(i, a);
  }
  return matched;
}

/// Least-squares horizontal motion over matched stems (2D Kabsch: the yaw from the summed cross
/// and dot products of the centred positions).
Motion2 fitMotion(const std::vector<std::pair<std::size_t, std::size_t>>& matched,
                  std::span<const StemMark> source, std::span<const StemMark> target) {
  Eigen::Vector2d mean_s = Eigen::Vector2d::Zero(), mean_t = Eigen::Vector2d::Zero();
  for (const auto& [i, a] : matched) {
    mean_s += source[i].position_m.head<2>();
    mean_t += target[a].position_m.head<2>();
  }
  mean_s /= static_cast<double>(matched.size());
  mean_t /= static_cast<double>(matched.size());
  double cross = 0.0, dot = 0.0;
  for (const auto& [i, a] : matched) {
    const Eigen::Vector2d s = source[i].position_m.head<2>() - mean_s;
    const Eigen::Vector2d t = target[a].position_m.head<2>() - mean_t;
    cross += s.x() * t.y() - s.y() * t.x();
    dot += s.dot(t);
  }
  Motion2 motion{.yaw_rad = std::atan2(cross, dot)};
  motion.t_m = mean_t - Eigen::Rotation2Dd(motion.yaw_rad) * mean_s;
  return motion;
}

}  // namespace

std::vector<StemMark> scanStemMarks(const PointCloud& scan_in_body, const lie::SO3& R_level_body) {
  std::vector<Eigen::Vector3d> levelled;
  levelled.reserve(scan_in_body.size());
  for (const Eigen::Vector3d& p : scan_in_body.positions)
    if (p.allFinite()) levelled.push_back(R_level_body * p);
  std::vector<StemMark> marks = cloudStemMarks(levelled);
  const lie::SO3 R_body_level = R_level_body.inverse();
  for (StemMark& mark : marks) mark.position_m = R_body_level * mark.position_m;
  return marks;
}

std::vector<StemMark> cloudStemMarks(std::span<const Eigen::Vector3d> points_m) {
  std::vector<StemMark> marks;
  for (const trees::Stem& stem : trees::takeInventory(points_m).stems)
    if (stem.quality != trees::StemQuality::kPoor) marks.push_back({stem.position_m, stem.dbh_m});
  return marks;
}

std::vector<StemMark> mergeStemMarks(std::span<const StemMark> marks, double merge_m) {
  struct Cluster {
    Eigen::Vector3d sum_m = Eigen::Vector3d::Zero();
    double dbh_sum_m = 0.0;
    std::size_t count = 0;
    Eigen::Vector2d centre() const { return sum_m.head<2>() / static_cast<double>(count); }
  };
  std::vector<Cluster> clusters;
  for (const StemMark& mark : marks) {
    auto near = std::find_if(clusters.begin(), clusters.end(), [&](const Cluster& c) {
      return (c.centre() - mark.position_m.head<2>()).norm() < merge_m;
    });
    if (near == clusters.end()) near = clusters.insert(clusters.end(), Cluster{});
    near->sum_m += mark.position_m;
    near->dbh_sum_m += mark.dbh_m;
    ++near->count;
  }
  std::vector<StemMark> merged;
  for (const Cluster& c : clusters) {
    const double n = static_cast<double>(c.count);
    merged.push_back({c.sum_m / n, c.dbh_sum_m / n});
  }
  return merged;
}

std::vector<ConstellationMatch> matchConstellations(std::span<const StemMark> source,
                                                    std::span<const StemMark> target,
                                                    const ConstellationOptions& options) {
  const std::vector<Pair> target_pairs = pairsOf(target, options);
  const TargetGrid grid(target, options.inlier_m);
  const auto inliers_of = [&](const Motion2& motion) {
    return inliersOf(motion, source, grid, target.size(), options);
  };
  struct Hypothesis {
    std::size_t inliers;
    Motion2 motion;
  };
  std::vector<Hypothesis> hypotheses;
  for (const Pair& s : pairsOf(source, options)) {
    const auto first = std::lower_bound(
        target_pairs.begin(), target_pairs.end(), s.distance_m - options.distance_tolerance_m,
        [](const Pair& p, double d_m) { return p.distance_m < d_m; });
    for (auto t = first;
         t != target_pairs.end() && t->distance_m <= s.distance_m + options.distance_tolerance_m;
         ++t) {
      // Both ways round: source a on target a and b on b, or crossed.
      for (const auto& [ta, tb] : {std::pair{t->a, t->b}, std::pair{t->b, t->a}}) {
        if (!sameDbh(source[s.a], target[ta], options) ||
            !sameDbh(source[s.b], target[tb], options))
          continue;
        const Eigen::Vector2d ds =
            source[s.b].position_m.head<2>() - source[s.a].position_m.head<2>();
        const Eigen::Vector2d dt =
            target[tb].position_m.head<2>() - target[ta].position_m.head<2>();
        Motion2 motion{.yaw_rad = std::atan2(dt.y(), dt.x()) - std::atan2(ds.y(), ds.x())};
        const Eigen::Vector2d mid_s =
            0.5 * (source[s.a].position_m.head<2>() + source[s.b].position_m.head<2>());
        const Eigen::Vector2d mid_t =
            0.5 * (target[ta].position_m.head<2>() + target[tb].position_m.head<2>());
        motion.t_m = mid_t - Eigen::Rotation2Dd(motion.yaw_rad) * mid_s;
        const std::size_t inliers = inliers_of(motion).size();
        if (inliers >= options.min_inliers) hypotheses.push_back({inliers, motion});
      }
    }
  }
  std::stable_sort(hypotheses.begin(), hypotheses.end(),
                   [](const Hypothesis& x, const Hypothesis& y) { return x.inliers > y.inliers; });

  std::vector<ConstellationMatch> matches;
  std::vector<Motion2> kept;
  for (const Hypothesis& h : hypotheses) {
    if (matches.size() >= options.max_matches) break;
    const auto matched = inliers_of(h.motion);
    const Motion2 refined = fitMotion(matched, source, target);
    const bool seen = std::any_of(kept.begin(), kept.end(), [&](const Motion2& k) {
      const double yaw_deg =
          std::abs(std::remainder(k.yaw_rad - refined.yaw_rad, 2.0 * std::numbers::pi)) * 180.0 /
          std::numbers::pi;
      return (k.t_m - refined.t_m).norm() < 1.0 && yaw_deg < 5.0;
    });
    if (seen) continue;
    kept.push_back(refined);
    const auto final_matched = inliers_of(refined);
    if (final_matched.size() < options.min_inliers) continue;
    double sum_m2 = 0.0;
    std::vector<double> dz_m;
    for (const auto& [i, a] : final_matched) {
      sum_m2 += (target[a].position_m.head<2>() - refined.apply(source[i].position_m.head<2>()))
                    .squaredNorm();
      dz_m.push_back(target[a].position_m.z() - source[i].position_m.z());
    }
    std::nth_element(dz_m.begin(), dz_m.begin() + dz_m.size() / 2, dz_m.end());
    const lie::SO3 R = lie::SO3::fromAxisAngle(Eigen::Vector3d::UnitZ(), refined.yaw_rad);
    matches.push_back(
        {lie::SE3(R, Eigen::Vector3d(refined.t_m.x(), refined.t_m.y(), dz_m[dz_m.size() / 2])),
         final_matched.size(), std::sqrt(sum_m2 / static_cast<double>(final_matched.size()))});
  }
  std::stable_sort(matches.begin(), matches.end(),
                   [](const ConstellationMatch& x, const ConstellationMatch& y) {
                     return std::tie(y.inliers, x.rms_m) < std::tie(x.inliers, y.rms_m);
                   });
  return matches;
}

}  // namespace taiga::mapping
