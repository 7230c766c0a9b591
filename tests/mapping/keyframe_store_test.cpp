// The disk-backed keyframe store: scans read back bit for bit, metadata and registration clouds
// in RAM, poses saved and reopened, and corrupt files reported with their name.
#include "taiga/mapping/keyframe_store.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <fmt/format.h>

#include <random>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/mapping/keyframe_file.hpp"

namespace taiga::mapping {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

// A scan-like cloud with every channel, values that do not survive a float round trip.
PointCloud randomScan(std::size_t n, double t_end_s, unsigned seed, bool with_columns = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coordinate(-40.0, 40.0), dt(0.0, 0.1);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    cloud.positions.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng) / 4.0);
    cloud.times_s.push_back(t_end_s - dt(rng));
    cloud.intensities.push_back(static_cast<float>(coordinate(rng) + 40.0) * 3.1f);
    cloud.rings.push_back(static_cast<std::uint16_t>(i % 128));
    if (with_columns) cloud.columns.push_back(static_cast<std::uint16_t>(i % 1024));
  }
  return cloud;
}

lie::SE3 somePose(double k) {
  return lie::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d(0.2, 0.3, 1.0).normalized())),
                  Eigen::Vector3d(k, -0.5 * k, 0.01 * k));
}

void expectSameCloud(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.times_s, b.times_s);
  EXPECT_EQ(a.intensities, b.intensities);
  EXPECT_EQ(a.rings, b.rings);
  EXPECT_EQ(a.columns, b.columns);
}

TEST(KeyframeStore, ScansReadBackBitForBitAndOnlyMetadataStaysInRam) {
  test::TempDir dir;
  KeyframeStore store = KeyframeStore::create(dir.path() / "keyframes");
  std::vector<PointCloud> scans;
  for (int k = 0; k < 3; ++k) {
    scans.push_back(randomScan(1000 + 10 * k, 100.0 + k, k, /*with_columns=*/k != 1));
    EXPECT_EQ(store.add(100.0 + k, somePose(k), scans.back()), static_cast<std::uint64_t>(k));
  }
  scans.push_back(PointCloud{});  // an empty scan is stored too
  store.add(104.0, somePose(3), scans.back());

  ASSERT_EQ(store.size(), 4u);
  for (std::uint64_t k = 0; k < 4; ++k) {
    expectSameCloud(store.load(k), scans[k]);
    EXPECT_EQ(store.info(k).point_count, scans[k].size());
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "keyframes" / fmt::format("{:06d}.tkf", k)));
    EXPECT_TRUE(store.registrationCloud(k)->empty());  // registration_voxel_m = 0: none kept
  }
  // 40 B per point with every channel (keyframe_file.hpp), 36 without columns.
  EXPECT_EQ(std::filesystem::file_size(store.keyframePath(0)), 40u + 1000u * 40u);
  EXPECT_EQ(std::filesystem::file_size(store.keyframePath(1)), 40u + 1010u * 38u);
  EXPECT_THROW(store.load(4), OutOfRangeError);
  EXPECT_THROW(store.add(104.0, somePose(4), scans[0]), std::invalid_argument);  // time not later
}

TEST(KeyframeStore, KeepsAVoxelFilteredCopyForRegistration) {
  test::TempDir dir;
  KeyframeStore store = KeyframeStore::create(dir.path(), {.registration_voxel_m = 0.4});
  // 8 points in one 0.4 m voxel and one far away: two registration points.
  PointCloud cloud;
  for (int i = 0; i < 8; ++i) cloud.positions.emplace_back(0.1 + 0.01 * i, 0.1, 0.1);
  cloud.positions.emplace_back(10.1, 10.1, 10.1);
  store.add(1.0, lie::SE3(), cloud);
  const auto registration = store.registrationCloud(0);
  ASSERT_EQ(registration->size(), 2u);
  EXPECT_NEAR(registration->positions[0].x(), 0.135, 1e-12);  // the voxel's centroid
  EXPECT_EQ(store.load(0).size(), 9u);                         // the full scan stays on disk
}

TEST(KeyframeStore, PosesAreSavedCorrectedAndReopened) {
  test::TempDir dir;
  {
    KeyframeStore store = KeyframeStore::create(dir.path());
    for (int k = 0; k < 5; ++k) store.add(10.0 + 0.5 * k, somePose(k), randomScan(50, 10.0 + 0.5 * k, k));
    // The mapping graph moves every keyframe by 1 m in x.
    std::vector<lie::SE3> corrected = store.poses();
    for (lie::SE3& T : corrected) T = lie::SE3(lie::SO3(), Eigen::Vector3d(1, 0, 0)) * T;
    store.setPoses(corrected);
    store.writePoses();
    EXPECT_THROW(store.setPoses({}), std::invalid_argument);
  }
  const KeyframeStore reopened = KeyframeStore::open(dir.path(), {.registration_voxel_m = 1.0});
  ASSERT_EQ(reopened.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(reopened.info(k).t_s, 10.0 + 0.5 * k);
    EXPECT_EQ(reopened.info(k).point_count, 50u);
    const lie::SE3 expected = lie::SE3(lie::SO3(), Eigen::Vector3d(1, 0, 0)) * somePose(k);
    EXPECT_EQ(reopened.pose(k).translation(), expected.translation());  // TUM text is exact
    EXPECT_FALSE(reopened.registrationCloud(k)->empty());
    expectSameCloud(reopened.load(k), randomScan(50, 10.0 + 0.5 * k, k));
  }
  // create() on the same directory starts afresh.
  EXPECT_EQ(KeyframeStore::create(dir.path()).size(), 0u);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "000000.tkf"));
}

TEST(KeyframeStore, CorruptOrTruncatedFilesAreErrorsNamingTheFile) {
  test::TempDir dir;
  {
    KeyframeStore store = KeyframeStore::create(dir.path());
    store.add(1.0, lie::SE3(), randomScan(100, 1.0, 1));
    store.add(2.0, lie::SE3(), randomScan(100, 2.0, 2));
    store.writePoses();
  }
  const std::filesystem::path first = dir.path() / "000000.tkf";
  const std::filesystem::path second = dir.path() / "000001.tkf";
  std::filesystem::resize_file(second, std::filesystem::file_size(second) - 3);
  EXPECT_THAT(messageOf<InputError>([&] { KeyframeStore::open(dir.path()); }),
              HasSubstr(second.string() + ": point count: the header announces 100 points"));
  EXPECT_THAT(messageOf<InputError>([&] { readKeyframeFile(second); }), HasSubstr("truncated"));

  std::string bytes = encodeKeyframe(0, 1.0, randomScan(3, 1.0, 1));
  bytes[0] = 'X';
  EXPECT_THAT(messageOf<InputError>([&] { decodeKeyframe(bytes, "k.tkf"); }),
              HasSubstr("k.tkf: not a taiga keyframe file"));
  bytes = encodeKeyframe(0, 1.0, randomScan(3, 1.0, 1));
  bytes[12] = 0x30;  // unknown channel bits
  EXPECT_THAT(messageOf<InputError>([&] { decodeKeyframe(bytes, "k.tkf"); }),
              HasSubstr("k.tkf: channels: unknown bits"));
  bytes = encodeKeyframe(0, 1.0, randomScan(3, 1.0, 1));
  bytes[39] = 0x7f;  // a point count of ~2^62
  EXPECT_THAT(messageOf<InputError>([&] { decodeKeyframe(bytes, "k.tkf"); }),
              HasSubstr("k.tkf: point count"));
  EXPECT_THAT(messageOf<InputError>([&] { decodeKeyframe(bytes.substr(0, 20), "k.tkf"); }),
              HasSubstr("shorter than the 40-byte header"));

  // A keyframe file that is not the one poses.tum lists.
  std::filesystem::copy_file(first, second, std::filesystem::copy_options::overwrite_existing);
  EXPECT_THAT(messageOf<InputError>([&] { KeyframeStore::open(dir.path()); }),
              HasSubstr(second.string() + ": keyframe 0 at t = 1 s, but " +
                        (dir.path() / "poses.tum").string() + " lists keyframe 1 at t = 2 s"));
  std::filesystem::remove(second);
  EXPECT_THAT(messageOf<InputError>([&] { KeyframeStore::open(dir.path()); }),
              HasSubstr(second.string() + ": missing"));
  EXPECT_THAT(messageOf<InputError>([&] { KeyframeStore::open(dir.path() / "nowhere"); }),
              HasSubstr("poses.tum: missing"));
}

}  // namespace
}  // namespace taiga::mapping
