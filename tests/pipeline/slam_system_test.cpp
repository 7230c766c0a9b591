// SlamSystem's event handling on short synthetic recordings (a few seconds, no simulator): every
// scan published once and in order, keyframes numbered as the store has them, GNSS fixes passed
// on in their order, and nothing published in the odometry's unlevelled start frame.
#include "taiga/pipeline/slam_system.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "../mapping/synthetic_forest.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::pipeline {
namespace {

namespace forest = mapping::forest;

/// Everything the system publishes, in order.
struct EventLog final : SlamObserver {
  struct Entry {
    std::string kind;  ///< scan, keyframe, fix
    double t_s = 0.0;
    std::uint64_t index = 0;  ///< scan index or keyframe id
    lie::SE3 T_odom_body;
  };
  std::vector<Entry> entries;
  std::size_t imu_samples = 0;

  void onScan(const ScanOutcome& scan, const lie::SE3&) override {
    entries.push_back({"scan", scan.t_s, scan.scan_index, scan.T_odom_body});
  }
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override {
    entries.push_back({"keyframe", scan.t_s, id, scan.T_odom_body});
  }
  void onGnssFix(const GnssFix& fix) override { entries.push_back({"fix", fix.t_s, 0, {}}); }
  void onImu(const ImuSample&) override { ++imu_samples; }
  std::size_t count(const std::string& kind) const {
    return static_cast<std::size_t>(std::count_if(entries.begin(), entries.end(),
                                                  [&](const Entry& e) { return e.kind == kind; }));
  }
};

constexpr double kScanPeriod_s = 0.1;

/// The synthetic forest with ground points dense enough for 1 m NDT cells (the stems, vertical,
/// do not constrain height).
std::vector<Eigen::Vector3d> forestInWorld(unsigned seed) {
  return forest::forestInWorld(seed, {.ground_spacing_m = 0.25});
}

/// A scan of the synthetic forest from T_world_body, already deskewed (every point at t_end_s).
io::Scan scanAt(const std::vector<Eigen::Vector3d>& forest_in_world, std::uint64_t index,
                double t_end_s, const lie::SE3& T_world_body) {
  io::Scan scan{.index = index, .t_start_s = t_end_s - kScanPeriod_s, .t_end_s = t_end_s};
  scan.cloud_in_lidar = forest::scanInBody(forest_in_world, T_world_body,
                                           static_cast<unsigned>(index) + 7, 25.0, 0.6);
  scan.cloud_in_lidar.times_s.assign(scan.cloud_in_lidar.size(), t_end_s);
  return scan;
}

GnssFix fixAt(double t_s) {
  return {.t_s = t_s,
          .latitude_deg = 60.2,
          .longitude_deg = 24.9,
          .height_ellipsoid_m = 30.0,
          .status = GnssStatus::kFix};
}

SystemConfig lidarOnlyConfig() {
  SystemConfig config;
  config.mapping.loop_closure = false;
  return config;
}

TEST(SlamSystem, LidarOnlyPublishesEveryScanOnceInOrderAndFollowsTheWalk) {
  const test::TempDir dir;
  const std::vector<Eigen::Vector3d> trees = forestInWorld(3);
  SlamSystem slam(lidarOnlyConfig(),
                  {.keyframe_dir = dir.path() / "keyframes", .lidar_only = true});
  EventLog log;
  slam.addObserver(log);
  // 3 s at 1 m/s along x, turning slowly; a GNSS fix every second.
  constexpr int kScans = 30;
  std::vector<lie::SE3> truth;
  for (int k = 0; k < kScans; ++k) {
    const double t_s = 1.0 + kScanPeriod_s * k;
    truth.push_back(forest::poseAt(-10.0 + 0.1 * k, 2.0, 1.5, 0.01 * k));
    slam.add(scanAt(trees, static_cast<std::uint64_t>(k), t_s, truth.back()));
    if (k % 10 == 5) slam.add(fixAt(t_s + 0.01));
  }
  const mapping::Mapper& mapper = slam.finish();

  ASSERT_EQ(log.count("scan"), static_cast<std::size_t>(kScans));
  EXPECT_EQ(log.count("fix"), 3u);
  // In order, each scan before its keyframe, keyframes numbered 0, 1, ... as the store has them.
  double last_t_s = 0.0;
  std::uint64_t next_keyframe = 0, next_scan = 0;
  for (const EventLog::Entry& e : log.entries) {
    EXPECT_GE(e.t_s, last_t_s) << e.kind;
    last_t_s = e.t_s;
    if (e.kind == "scan") {
      EXPECT_EQ(e.index, next_scan++);
    }
    if (e.kind == "keyframe") {
      EXPECT_EQ(e.index, next_keyframe++);
      EXPECT_EQ(slam.keyframes().info(e.index).t_s, e.t_s);
    }
  }
  EXPECT_EQ(next_keyframe, slam.keyframes().size());
  EXPECT_EQ(mapper.graph().size(), slam.keyframes().size());
  EXPECT_GE(slam.keyframes().size(), 3u);  // 2.9 m walked, a keyframe per metre
  // The odom frame is the first scan's body frame: the odometry follows the true relative motion
  // (measured: 6.3 cm off after 2.9 m, mostly short along the walk, on this sparse scene;
  // without working registration the constant-velocity prior would stay at the start).
  const lie::SE3 T_true_first_last = truth.front().inverse() * truth.back();
  const lie::SE3& T_odom_last = log.entries.back().kind == "scan"
                                    ? log.entries.back().T_odom_body
                                    : log.entries[log.entries.size() - 2].T_odom_body;
  EXPECT_LT((T_odom_last.translation() - T_true_first_last.translation()).norm(), 0.10)
      << (T_odom_last.translation() - T_true_first_last.translation()).transpose();
  // finish() gave the store the graph's final poses.
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k)
    EXPECT_EQ(slam.keyframes().pose(k).matrix(), mapper.graph().pose(k).matrix());
  // The registration copies the store was handed (the odometry's source clouds) are those it
  // makes from the keyframe files itself, bit for bit.
  const mapping::KeyframeStore reopened = mapping::KeyframeStore::open(
      dir.path() / "keyframes", {.registration_voxel_m = SystemConfig().odometry.voxel_size_m});
  for (std::size_t k = 0; k < slam.keyframes().size(); ++k)
    EXPECT_EQ(slam.keyframes().registrationCloud(k)->positions,
              reopened.registrationCloud(k)->positions);
}

TEST(SlamSystem, WithAnImuNothingIsPublishedBeforeTheOdomFrameIsLevelled) {
  const test::TempDir dir;
  const std::vector<Eigen::Vector3d> trees = forestInWorld(5);
  SystemConfig config = lidarOnlyConfig();
  config.odometry.gravity_alignment_s = 1.0;
  SlamSystem slam(config, {.keyframe_dir = dir.path() / "keyframes"});
  EventLog log;
  slam.addObserver(log);
  // A rig standing still and level: the IMU at 200 Hz reads gravity's reaction.
  const lie::SE3 T_world_body = forest::poseAt(0.0, 0.0, 1.5, 0.3);
  ImuSample still{.acceleration_imu_mps2 =
                      Eigen::Vector3d(0.0, 0.0, config.odometry.imu.gravity_mps2)};
  std::vector<std::size_t> published_after_scan;
  std::uint64_t scan_index = 0;
  for (int i = 0; i <= 800; ++i) {  // 4 s
    still.t_s = 0.005 * i;
    slam.add(still);
    if (i % 20 == 0 && i > 0) {
      slam.add(scanAt(trees, scan_index++, still.t_s, T_world_body));
      published_after_scan.push_back(log.entries.size());
    }
    if (i % 100 == 50 && i > 200) slam.add(fixAt(still.t_s));
  }
  slam.finish();
  EXPECT_EQ(log.imu_samples, 801u);

  // The IMU initializes over 0.5 s, the first scan after it waits for the second, and the
  // alignment spans 1 s of scans (from 0.5 s): nothing before 1.5 s, everything held then at once.
  for (std::size_t k = 0; k < published_after_scan.size(); ++k) {
    const double t_s = kScanPeriod_s * static_cast<double>(k + 1);
    if (t_s < 1.45) {
      EXPECT_EQ(published_after_scan[k], 0u) << "after the scan at " << t_s << " s";
    }
  }
  EXPECT_GT(published_after_scan.back(), 0u);
  ASSERT_GE(log.count("scan"), 30u);
  EXPECT_EQ(log.count("fix"), 6u);
  double last_t_s = 0.0;
  for (const EventLog::Entry& e : log.entries) {
    EXPECT_GE(e.t_s, last_t_s) << e.kind;  // held events keep their order
    last_t_s = e.t_s;
    // Standing still: every published pose is at the start, level.
    if (e.kind != "scan") continue;
    EXPECT_LT(e.T_odom_body.translation().norm(), 0.05) << e.t_s;
    const Eigen::Vector3d z_body_in_odom = e.T_odom_body.rotation() * Eigen::Vector3d::UnitZ();
    EXPECT_GT(z_body_in_odom.z(), std::cos(0.5 * kRadPerDeg)) << e.t_s;
  }
}

}  // namespace
}  // namespace taiga::pipeline
