// The odometry's health on short synthetic walks (lidar-only, no simulator), with faults put in:
// a scan from another place spliced into the walk, and a stretch of scans that see nothing the
// map knows. Every scan is judged; a scan that is far off is never `ok`; a distrusted scan never
// becomes a keyframe; the track recovers where the data allow and says it was lost where not.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "../mapping/synthetic_forest.hpp"
#include "taiga/pipeline/odometry.hpp"

namespace taiga::pipeline {
namespace {

namespace forest = mapping::forest;

constexpr double kScanPeriod_s = 0.1;

/// A deskewed scan (every point at its end) of `world` from T_world_body.
io::Scan scanAt(const std::vector<Eigen::Vector3d>& world, std::uint64_t index,
                const lie::SE3& T_world_body) {
  const double t_end_s = 1.0 + kScanPeriod_s * static_cast<double>(index);
  io::Scan scan{.index = index, .t_start_s = t_end_s, .t_end_s = t_end_s};
  scan.cloud_in_lidar =
      forest::scanInBody(world, T_world_body, static_cast<unsigned>(index) + 7, 25.0, 0.6);
  scan.cloud_in_lidar.times_s.assign(scan.cloud_in_lidar.size(), t_end_s);
  return scan;
}

/// 1 m/s along x with a slow turn.
lie::SE3 truthAt(int k) { return forest::poseAt(-10.0 + 0.1 * k, 2.0, 1.5, 0.01 * k); }

struct Walk {
  std::vector<ScanOutcome> outcomes;
  /// Position error of each outcome against the truth, in the odom frame (the first scan's body
  /// frame).
  std::vector<double> errors_m;
};

/// Runs the lidar-only odometry over `kScans` scans; `replace(k)` may give another scan for k.
template <class Replace>
Walk walk(int scans, Replace replace) {
  const std::vector<Eigen::Vector3d> trees = forest::forestInWorld(3, {.ground_spacing_m = 0.25});
  // Every scan of this world holds the same exact lattice points (a subset of them): with the
  // measured voxel points a scan finds its points' twins in the map, which no sensor gives, and
  // the fitness swings 6x between keyframes. The health checks are tested on centroids.
  OdometryConfig config;
  config.voxel_point = "centroid";
  Odometry odometry(config, RigConfig{}, /*lidar_only=*/true);
  Walk w;
  for (int k = 0; k < scans; ++k) {
    const auto index = static_cast<std::uint64_t>(k);
    std::optional<io::Scan> scan = replace(k, index);
    for (ScanOutcome& o : odometry.addScan(scan ? *scan : scanAt(trees, index, truthAt(k)))) {
      const lie::SE3 truth = truthAt(0).inverse() * truthAt(static_cast<int>(o.scan_index));
      w.errors_m.push_back((o.T_odom_body.translation() - truth.translation()).norm());
      w.outcomes.push_back(std::move(o));
    }
  }
  return w;
}

/// No scan more than `limit_m` off is `ok`.
void expectNoSilentError(const Walk& w, double limit_m) {
  for (std::size_t i = 0; i < w.outcomes.size(); ++i) {
    if (w.errors_m[i] <= limit_m) continue;
    EXPECT_NE(w.outcomes[i].health.status, ScanStatus::kOk)
        << "scan " << w.outcomes[i].scan_index << " is " << w.errors_m[i] << " m off";
  }
}

TEST(OdometryHealth, ACleanWalkIsOkThroughout) {
  const Walk w = walk(40, [](int, std::uint64_t) { return std::optional<io::Scan>(); });
  ASSERT_EQ(w.outcomes.size(), 40u);
  for (const ScanOutcome& o : w.outcomes)
    EXPECT_EQ(o.health.status, ScanStatus::kOk) << o.scan_index << ": " << o.health.reason;
  EXPECT_LT(w.errors_m.back(), 0.15);
}

TEST(OdometryHealth, AScanFromAnotherPlaceIsNotOkAndNeverAKeyframe) {
  const std::vector<Eigen::Vector3d> elsewhere =
      forest::forestInWorld(11, {.ground_spacing_m = 0.25});
  constexpr int kSpliced = 20;
  const Walk w = walk(40, [&](int k, std::uint64_t index) {
    if (k != kSpliced) return std::optional<io::Scan>();
    return std::optional(scanAt(elsewhere, index, forest::poseAt(5.0, -8.0, 1.5, 2.0)));
  });
  ASSERT_EQ(w.outcomes.size(), 40u);
  const ScanOutcome& spliced = w.outcomes[kSpliced];
  EXPECT_NE(spliced.health.status, ScanStatus::kOk) << spliced.health.reason;
  EXPECT_FALSE(spliced.keyframe_id);
  expectNoSilentError(w, 0.5);
  // The walk goes on: the scans after it are ok again and on track.
  EXPECT_EQ(w.outcomes.back().health.status, ScanStatus::kOk) << w.outcomes.back().health.reason;
  EXPECT_LT(w.errors_m.back(), 0.3);
}

/// A scan that keeps only the points whose azimuth lies in [0, keep_deg) in the body frame
/// (the rest of the sweep's packets lost, or the lidar blinded by the crane or mud).
io::Scan wedgeScanAt(const std::vector<Eigen::Vector3d>& world, std::uint64_t index,
                     const lie::SE3& T_world_body, double keep_deg) {
  io::Scan scan = scanAt(world, index, T_world_body);
  PointCloud kept;
  for (const Eigen::Vector3d& p : scan.cloud_in_lidar.positions) {
    double azimuth_deg = std::atan2(p.y(), p.x()) * 180.0 / 3.141592653589793;
    if (azimuth_deg < 0.0) azimuth_deg += 360.0;
    if (azimuth_deg < keep_deg) kept.positions.push_back(p);
  }
  kept.times_s.assign(kept.size(), scan.t_end_s);
  scan.cloud_in_lidar = std::move(kept);
  return scan;
}

/// Nearly blind: a sliver of 1 deg, a few dozen points.
io::Scan blindScanAt(const std::vector<Eigen::Vector3d>& world, std::uint64_t index,
                     const lie::SE3& T_world_body) {
  return wedgeScanAt(world, index, T_world_body, 1.0);
}

/// A walk blinded for the scans [from, to).
Walk blindedWalk(int scans, int from, int to) {
  const std::vector<Eigen::Vector3d> trees = forest::forestInWorld(3, {.ground_spacing_m = 0.25});
  return walk(scans, [&](int k, std::uint64_t index) {
    if (k < from || k >= to) return std::optional<io::Scan>();
    return std::optional(blindScanAt(trees, index, truthAt(k)));
  });
}

TEST(OdometryHealth, NinetyPercentOfPacketsLostForTwoSecondsIsNeverSilentlyWrong) {
  const std::vector<Eigen::Vector3d> trees = forest::forestInWorld(3, {.ground_spacing_m = 0.25});
  const Walk w = walk(60, [&](int k, std::uint64_t index) {
    if (k < 20 || k >= 40) return std::optional<io::Scan>();
    return std::optional(wedgeScanAt(trees, index, truthAt(k), 36.0));
  });
  ASSERT_EQ(w.outcomes.size(), 60u);
  expectNoSilentError(w, 0.5);
  EXPECT_EQ(w.outcomes.back().health.status, ScanStatus::kOk) << w.outcomes.back().health.reason;
  EXPECT_EQ(w.outcomes.back().map_segment, 0u);
  EXPECT_LT(w.errors_m.back(), 0.3);
}

TEST(OdometryHealth, ABlindStretchIsLostThenRecoversOnTheSameMap) {
  // 1.5 s blind: longer than lost_after_s (1 s), shorter than lost_after_s +
  // reinitialize_after_s: the constant velocity carries the pose, and the scans after it
  // register to the same local map again.
  const Walk w = blindedWalk(50, 15, 30);
  ASSERT_EQ(w.outcomes.size(), 50u);
  std::size_t lost = 0;
  for (int k = 15; k < 30; ++k) {
    EXPECT_NE(w.outcomes[k].health.status, ScanStatus::kOk) << k;
    EXPECT_FALSE(w.outcomes[k].keyframe_id) << k;
    lost += w.outcomes[k].health.status == ScanStatus::kLost;
  }
  EXPECT_GT(lost, 0u);
  EXPECT_EQ(w.outcomes.back().health.status, ScanStatus::kOk);
  EXPECT_EQ(w.outcomes.back().map_segment, 0u);
  expectNoSilentError(w, 0.5);
  EXPECT_LT(w.errors_m.back(), 0.3);
}

TEST(OdometryHealth, ALongBlindStretchStartsANewMapSegment) {
  const Walk w = blindedWalk(70, 10, 50);  // 4 s blind
  ASSERT_EQ(w.outcomes.size(), 70u);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(w.outcomes[k].health.status, ScanStatus::kOk) << k;
  EXPECT_EQ(w.outcomes[45].health.status, ScanStatus::kLost);
  // The old segment's scans are never silently wrong; the new segment is not tied to the old
  // one (dead reckoning placed it), so it is judged on its own motion.
  for (std::size_t i = 0; i < w.outcomes.size(); ++i) {
    const ScanOutcome& o = w.outcomes[i];
    if (o.map_segment == 0 && w.errors_m[i] > 0.5) {
      EXPECT_NE(o.health.status, ScanStatus::kOk) << "scan " << i << " is " << w.errors_m[i];
    }
  }
  const ScanOutcome& last = w.outcomes.back();
  ASSERT_GT(last.map_segment, 0u);
  EXPECT_EQ(last.health.status, ScanStatus::kOk) << last.health.reason;
  // The last segment follows the true relative motion from its first scan on. (A segment seeded
  // by a blind scan cannot grow: the next restart seeds it again.)
  int first = 69;
  while (first > 0 && w.outcomes[first - 1].map_segment == last.map_segment) --first;
  ASSERT_LE(first, 64);
  const lie::SE3 moved = w.outcomes[first].T_odom_body.inverse() * last.T_odom_body;
  const lie::SE3 truth_moved = truthAt(first).inverse() * truthAt(69);
  EXPECT_LT((moved.translation() - truth_moved.translation()).norm(), 0.2);
}

}  // namespace
}  // namespace taiga::pipeline
