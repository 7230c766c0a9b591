// Map export from the keyframe store: every point transformed by its keyframe's pose into LAS
// with its time, intensity, ring and keyframe id; global voxel decimation keeps the point nearest
// each voxel's centre across keyframes.
#include "taiga/mapping/map_export.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <set>

#include "../support/temp_dir.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_reader.hpp"

namespace taiga::mapping {
namespace {

lie::SE3 poseOf(int k) {
  return lie::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitZ())),
                  Eigen::Vector3d(2.0 * k, 1.0, 0.5));
}

// A 1 m grid of points on a wall seen from keyframe k (body frame): the same world points from
// every keyframe, so that decimation has duplicates to remove.
PointCloud wallInBody(int k, double t_s) {
  PointCloud cloud;
  const lie::SE3 T_body_world = poseOf(k).inverse();
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 5; ++j) {
      cloud.positions.push_back(T_body_world * Eigen::Vector3d(0.5 + i, 20.0 + 0.01 * k, 0.5 + j));
      cloud.times_s.push_back(t_s - 0.001 * (i * 5 + j));
      cloud.intensities.push_back(static_cast<float>(10 * k + i));
      cloud.rings.push_back(static_cast<std::uint16_t>(j));
    }
  }
  return cloud;
}

struct StoreFixture {
  test::TempDir dir;
  KeyframeStore store = KeyframeStore::create(dir.path() / "keyframes");
  std::vector<lie::SE3> poses;
  StoreFixture() {
    for (int k = 0; k < 4; ++k) {
      store.add(100.0 + k, poseOf(k), wallInBody(k, 100.0 + k));
      poses.push_back(poseOf(k));
    }
  }
};

TEST(MapExport, EveryPointLandsInTheWorldWithItsTimeIntensityRingAndKeyframe) {
  StoreFixture f;
  const auto las = f.dir.file("map.las");
  const MapExportSummary summary = exportMap(f.store, f.poses, las, {.write_ply = true});
  EXPECT_EQ(summary.points_read, 200u);
  EXPECT_EQ(summary.points_written, 200u);

  io::LasReader reader(las);
  std::vector<std::uint16_t> ids;
  const PointCloud map = reader.readStrided(1, &ids);
  ASSERT_EQ(map.size(), 200u);
  for (int k = 0; k < 4; ++k) {
    const PointCloud body = wallInBody(k, 100.0 + k);
    for (std::size_t i = 0; i < body.size(); ++i) {
      const std::size_t m = 50 * k + i;
      EXPECT_LT((map.positions[m] - poseOf(k) * body.positions[i]).cwiseAbs().maxCoeff(),
                0.0005 + 1e-9);
      EXPECT_EQ(map.times_s[m], body.times_s[i]);
      EXPECT_EQ(map.intensities[m], body.intensities[i]);
      EXPECT_EQ(map.rings[m], body.rings[i]);
      EXPECT_EQ(ids[m], k);
    }
  }
  const io::LoadedPoints ply = io::readCloudFile(f.dir.file("map.ply"));
  EXPECT_EQ(std::size_t{ply.packed.width} * ply.packed.height, 200u);

  // A corrected pose moves that keyframe's points, and T_out_map moves all of them.
  std::vector<lie::SE3> corrected = f.poses;
  corrected[2] = lie::SE3(lie::SO3(), Eigen::Vector3d(0, 0, 1)) * corrected[2];
  exportMap(f.store, corrected, las,
            {.T_out_map = Eigen::Affine3d(Eigen::Translation3d(385000.0, 6672000.0, 0.0))});
  const PointCloud moved = io::LasReader(las).readStrided(1);
  EXPECT_NEAR(moved.positions[0].x() - map.positions[0].x(), 385000.0, 0.001);
  EXPECT_NEAR(moved.positions[100].z() - map.positions[100].z(), 1.0, 0.001);
  EXPECT_NEAR(moved.positions[150].z() - map.positions[150].z(), 0.0, 0.001);
}

TEST(MapExport, GlobalVoxelFilterKeepsOnePointPerVoxelNearestItsCentre) {
  StoreFixture f;
  const auto las = f.dir.file("map.las");
  // 1 m voxels: the wall points sit at voxel centres in x and z; the four keyframes see them at
  // y = 20.00, 20.01, 20.02, 20.03, and the voxel centre is at y = 20.5, so keyframe 3's copy of
  // each point is the nearest: 50 voxels, all from keyframe 3.
  const MapExportSummary summary = exportMap(f.store, f.poses, las, {.voxel_m = 1.0});
  EXPECT_EQ(summary.points_read, 200u);
  EXPECT_EQ(summary.points_written, 50u);
  std::vector<std::uint16_t> ids;
  const PointCloud map = io::LasReader(las).readStrided(1, &ids);
  ASSERT_EQ(map.size(), 50u);
  std::set<std::tuple<int, int, int>> voxels;
  for (std::size_t m = 0; m < map.size(); ++m) {
    EXPECT_EQ(ids[m], 3);
    EXPECT_NEAR(map.positions[m].y(), 20.03, 0.0006);
    voxels.insert({int(std::floor(map.positions[m].x())), int(std::floor(map.positions[m].y())),
                   int(std::floor(map.positions[m].z()))});
    EXPECT_GE(map.intensities[m], 30.0f);  // keyframe 3's own intensity travels with the point
  }
  EXPECT_EQ(voxels.size(), 50u);
  // Voxels of 5 mm are finer than the 1 cm between the keyframes' copies: nothing is removed.
  EXPECT_EQ(exportMap(f.store, f.poses, las, {.voxel_m = 0.005}).points_written, 200u);
  EXPECT_THROW(exportMap(f.store, {}, las), std::invalid_argument);
}

// A run's map segment that was never re-attached goes to a file of its own: `keep` selects the
// keyframes, with and without decimation.
TEST(MapExport, KeepSelectsTheKeyframes) {
  StoreFixture f;
  const auto las = f.dir.file("map.las");
  const auto odd = [](std::uint64_t id) { return id % 2 == 1; };
  for (const double voxel_m : {0.0, 0.005}) {
    const MapExportSummary summary =
        exportMap(f.store, f.poses, las, {.voxel_m = voxel_m, .keep = odd});
    EXPECT_EQ(summary.keyframes, 2u);
    EXPECT_EQ(summary.points_written, 100u);
    std::vector<std::uint16_t> ids;
    io::LasReader(las).readStrided(1, &ids);
    EXPECT_EQ(std::set<std::uint16_t>(ids.begin(), ids.end()), (std::set<std::uint16_t>{1, 3}));
  }
}

}  // namespace
}  // namespace taiga::mapping
