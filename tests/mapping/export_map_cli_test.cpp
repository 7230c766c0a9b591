// `taiga export-map KEYFRAMES_DIR --out FILE.las`: a finished run's map written again from its
// keyframe store, and a corrupt store reported with the file's name and exit code 2.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/mapping/keyframe_store.hpp"

namespace taiga::mapping {
namespace {

using ::testing::HasSubstr;

using Result = test::TaigaResult;
using test::runTaiga;

TEST(ExportMapCli, WritesTheMapAgainWithTheStoredPosesAndDecimation) {
  test::TempDir dir;
  {
    KeyframeStore store = KeyframeStore::create(dir.path() / "keyframes");
    PointCloud cloud;
    for (int i = 0; i < 100; ++i) cloud.positions.emplace_back(0.01 * i, 0.0, 0.0);  // 1 m of points
    store.add(1.0, lie::SE3(lie::SO3(), Eigen::Vector3d(10, 0, 0)), cloud);
    store.add(2.0, lie::SE3(lie::SO3(), Eigen::Vector3d(20, 0, 0)), cloud);
    store.writePoses();
  }
  const std::string keyframes = (dir.path() / "keyframes").string();
  const Result full = runTaiga("export-map " + keyframes + " --out " + dir.file("map.las").string());
  ASSERT_EQ(full.exit_code, 0) << full.output;
  EXPECT_THAT(full.output, HasSubstr("2 keyframes, 200 points read, 200 written"));
  const PointCloud map = io::LasReader(dir.file("map.las")).readStrided(1);
  ASSERT_EQ(map.size(), 200u);
  EXPECT_NEAR(map.positions[150].x(), 20.5, 0.0006);  // keyframe 1's pose applied

  const Result decimated = runTaiga("export-map " + keyframes + " --out " +
                                    dir.file("coarse.las").string() + " --map-voxel 0.5 --ply");
  ASSERT_EQ(decimated.exit_code, 0) << decimated.output;
  EXPECT_EQ(io::LasReader(dir.file("coarse.las")).pointCount(), 4u);  // 2 voxels per keyframe
  EXPECT_TRUE(std::filesystem::exists(dir.file("coarse.ply")));

  std::filesystem::resize_file(dir.path() / "keyframes" / "000001.tkf", 100);
  const Result corrupt = runTaiga("export-map " + keyframes + " --out " + dir.file("x.las").string());
  EXPECT_EQ(corrupt.exit_code, 2);
  EXPECT_THAT(corrupt.output, HasSubstr("000001.tkf: point count"));
}

}  // namespace
}  // namespace taiga::mapping
