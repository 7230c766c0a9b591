// MappingThread's outputs while a run is still going: the live poses.tum that `taiga export-map`
// reads (issue 7: the map on demand while running), and the graph snapshots the odometry
// rebuilds its local map from.
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "taiga/mapping/map_export.hpp"
#include "taiga/mapping/mapper.hpp"

namespace taiga::mapping {
namespace {

PointCloud lineOfPoints() {
  PointCloud cloud;
  for (int i = 0; i < 50; ++i) cloud.positions.emplace_back(0.02 * i, 0.0, 0.0);
  return cloud;
}

lie::SE3 poseAt(double x_m) { return lie::SE3(lie::SO3(), Eigen::Vector3d(x_m, 0.0, 0.0)); }

TEST(MappingThread, PublishesItsPosesSoARunningRunCanBeExported) {
  const test::TempDir dir;
  KeyframeStore store = KeyframeStore::create(dir.path());
  MappingThread thread(MappingConfig{}, OdometryConfig{}, store,
                       {.snapshot_keyframes = 2, .after_keyframe = [&store](const Mapper& mapper) {
                          store.writePoses(mapper.keyframeTrajectory());
                        }});
  for (std::size_t k = 0; k < 3; ++k) {
    const double t_s = 1.0 + static_cast<double>(k);
    const std::uint64_t id = store.add(t_s, poseAt(2.0 * k), lineOfPoints());
    thread.addKeyframe(id, t_s, poseAt(2.0 * k));
  }
  // A fourth keyframe in the store that the mapping thread has not been told of yet.
  store.add(4.0, poseAt(6.0), lineOfPoints());

  const std::optional<GraphSnapshot> snapshot = thread.waitForSnapshot(2);
  ASSERT_TRUE(snapshot.has_value());
  EXPECT_EQ(snapshot->keyframe, 2u);
  ASSERT_EQ(snapshot->poses_T_map_body.size(), 2u);  // keyframes 1 and 2
  EXPECT_NEAR(snapshot->poses_T_map_body[0].translation().x(), 2.0, 1e-12);
  EXPECT_NEAR(snapshot->poses_T_map_body[1].translation().x(), 4.0, 1e-12);

  // While the thread still runs: the store on disk lists the keyframes the graph holds, and the
  // map exports from it.
  const KeyframeStore live = KeyframeStore::open(dir.path());
  ASSERT_EQ(live.size(), 3u);
  EXPECT_NEAR(live.pose(2).translation().x(), 4.0, 1e-12);
  const MapExportSummary map = exportMap(live, live.poses(), dir.file("live.las"));
  EXPECT_EQ(map.keyframes, 3u);
  EXPECT_EQ(map.points_written, 150u);
  thread.finish();
}

TEST(MappingThread, SnapshotsAreTakenInOrderAndOlderOnesDropped) {
  const test::TempDir dir;
  const KeyframeStore store = KeyframeStore::create(dir.path());
  MappingThread thread(MappingConfig{}, OdometryConfig{}, store, {.snapshot_keyframes = 3});
  for (std::size_t k = 0; k < 5; ++k) thread.addKeyframe(k, 1.0 + k, poseAt(1.0 * k));
  const std::optional<GraphSnapshot> third = thread.waitForSnapshot(3);
  ASSERT_TRUE(third.has_value());
  ASSERT_EQ(third->poses_T_map_body.size(), 3u);  // keyframes 1, 2, 3
  EXPECT_NEAR(third->poses_T_map_body.front().translation().x(), 1.0, 1e-12);
  EXPECT_FALSE(thread.waitForSnapshot(1).has_value());  // dropped when 3 was taken
  EXPECT_EQ(thread.waitForSnapshot(4)->keyframe, 4u);
  thread.finish();
}

TEST(MappingThread, WaitingWithoutSnapshotsIsAProgrammingError) {
  const test::TempDir dir;
  const KeyframeStore store = KeyframeStore::create(dir.path());
  MappingThread thread(MappingConfig{}, OdometryConfig{}, store);
  EXPECT_THROW(thread.waitForSnapshot(0), std::logic_error);
}

}  // namespace
}  // namespace taiga::mapping
