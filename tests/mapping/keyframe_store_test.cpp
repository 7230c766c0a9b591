// The disk-backed keyframe store: scans read back bit for bit, metadata in RAM, registration
// copies in a bounded least-recently-used cache and rebuilt from disk bit for bit, poses saved
// and reopened, and corrupt files reported with their name.
#include "taiga/mapping/keyframe_store.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <random>
#include <thread>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/mapping/keyframe_file.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

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

// The odometry hands the store its source cloud, the scan filtered as the copies are: kept as is.
TEST(KeyframeStore, KeepsTheRegistrationCopyItIsGiven) {
  test::TempDir dir;
  KeyframeStore store = KeyframeStore::create(dir.path(), {.registration_voxel_m = 0.4});
  const PointCloud scan = randomScan(2000, 1.0, 7);
  const std::vector<Eigen::Vector3d> filtered = preprocess::voxelFilter(scan, 0.4).positions;
  store.add(1.0, lie::SE3(), scan, &filtered);
  EXPECT_EQ(store.registrationCloud(0)->positions, filtered);
  EXPECT_EQ(store.registrationCacheStatistics().rebuilt, 0u);
  expectSameCloud(store.load(0), scan);
}

// The registration copy add() makes: the scan's 0.4 m voxel centroids, positions only.
std::vector<Eigen::Vector3d> expectedRegistrationPositions(const PointCloud& scan_in_body) {
  return preprocess::voxelFilter(scan_in_body, 0.4).positions;
}

// Scans whose registration copies differ from one keyframe to the next.
std::vector<PointCloud> distinctScans(std::size_t count) {
  std::vector<PointCloud> scans;
  for (std::size_t k = 0; k < count; ++k)
    scans.push_back(randomScan(3000 + 37 * k, 100.0 + static_cast<double>(k),
                               static_cast<unsigned>(100 + k)));
  return scans;
}

TEST(KeyframeStore, ACacheSmallerThanTheStoreGivesTheSameCopiesBitForBitInAnyOrder) {
  test::TempDir dir;
  constexpr std::size_t kKeyframes = 12;
  constexpr std::size_t kCapacity = 3;
  const std::vector<PointCloud> scans = distinctScans(kKeyframes);
  // The reference: a cache holding every copy, as the store kept them all before the cache.
  KeyframeStore uncached =
      KeyframeStore::create(dir.path() / "uncached",
                            {.registration_voxel_m = 0.4, .registration_cache_keyframes = kKeyframes});
  KeyframeStore cached = KeyframeStore::create(
      dir.path() / "cached", {.registration_voxel_m = 0.4, .registration_cache_keyframes = kCapacity});
  for (std::size_t k = 0; k < kKeyframes; ++k) {
    const double t_s = 100.0 + static_cast<double>(k);
    uncached.add(t_s, somePose(static_cast<double>(k)), scans[k]);
    cached.add(t_s, somePose(static_cast<double>(k)), scans[k]);
    EXPECT_LE(cached.registrationCacheStatistics().cached_keyframes, kCapacity);
  }
  EXPECT_EQ(cached.registrationCacheStatistics().cached_keyframes, kCapacity);
  EXPECT_EQ(uncached.registrationCacheStatistics().cached_keyframes, kKeyframes);

  // Every id several times, in a random order: hits and rebuilds from disk mixed.
  std::vector<std::uint64_t> order;
  for (int pass = 0; pass < 4; ++pass)
    for (std::uint64_t id = 0; id < kKeyframes; ++id) order.push_back(id);
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (const std::uint64_t id : order) {
    const std::shared_ptr<const PointCloud> copy = cached.registrationCloud(id);
    const std::shared_ptr<const PointCloud> reference = uncached.registrationCloud(id);
    ASSERT_EQ(copy->size(), reference->size()) << "keyframe " << id;
    EXPECT_EQ(copy->positions, reference->positions) << "keyframe " << id;  // bit for bit
    EXPECT_EQ(copy->positions, expectedRegistrationPositions(scans[id])) << "keyframe " << id;
    // Loop closure registers positions only: no other channel is kept.
    EXPECT_TRUE(copy->times_s.empty() && copy->intensities.empty() && copy->rings.empty() &&
                copy->columns.empty());
    EXPECT_LE(cached.registrationCacheStatistics().cached_keyframes, kCapacity);
  }
  const RegistrationCacheStatistics statistics = cached.registrationCacheStatistics();
  EXPECT_GT(statistics.rebuilt, 0u);  // the copies did come from disk
  EXPECT_GT(statistics.hits, 0u);
  EXPECT_EQ(statistics.hits + statistics.rebuilt, order.size());
  EXPECT_EQ(uncached.registrationCacheStatistics().rebuilt, 0u);
  EXPECT_THROW(cached.registrationCloud(kKeyframes), OutOfRangeError);
}

TEST(KeyframeStore, TheLeastRecentlyUsedCopyIsEvictedAndACopyHandedOutOutlivesEviction) {
  test::TempDir dir;
  const std::vector<PointCloud> scans = distinctScans(4);
  KeyframeStore store =
      KeyframeStore::create(dir.path(), {.registration_voxel_m = 0.4, .registration_cache_keyframes = 2});
  store.add(100.0, somePose(0), scans[0]);
  store.add(101.0, somePose(1), scans[1]);  // cached: 1, 0
  const std::shared_ptr<const PointCloud> copy_0 = store.registrationCloud(0);  // cached: 0, 1
  EXPECT_EQ(store.registrationCacheStatistics().hits, 1u);
  store.add(102.0, somePose(2), scans[2]);  // cached: 2, 0; 1 evicted
  store.registrationCloud(0);
  EXPECT_EQ(store.registrationCacheStatistics().rebuilt, 0u);
  store.registrationCloud(1);  // rebuilt; cached: 1, 0; 2 evicted
  EXPECT_EQ(store.registrationCacheStatistics().rebuilt, 1u);
  store.add(103.0, somePose(3), scans[3]);  // cached: 3, 1; 0 evicted
  store.registrationCloud(2);               // rebuilt; cached: 2, 3
  EXPECT_EQ(store.registrationCacheStatistics().rebuilt, 2u);
  EXPECT_EQ(store.registrationCacheStatistics().cached_keyframes, 2u);
  // Keyframe 0's copy is no longer cached, but the one handed out is intact.
  EXPECT_EQ(copy_0->positions, expectedRegistrationPositions(scans[0]));
  const std::shared_ptr<const PointCloud> copy_0_again = store.registrationCloud(0);
  EXPECT_EQ(store.registrationCacheStatistics().rebuilt, 3u);
  EXPECT_NE(copy_0_again, copy_0);
  EXPECT_EQ(copy_0_again->positions, copy_0->positions);

  // Capacity 0: nothing stays in RAM, every copy comes from disk.
  KeyframeStore uncached = KeyframeStore::create(
      dir.path() / "none", {.registration_voxel_m = 0.4, .registration_cache_keyframes = 0});
  uncached.add(100.0, somePose(0), scans[0]);
  EXPECT_EQ(uncached.registrationCacheStatistics().cached_keyframes, 0u);
  EXPECT_EQ(uncached.registrationCloud(0)->positions, expectedRegistrationPositions(scans[0]));
  EXPECT_EQ(uncached.registrationCacheStatistics().rebuilt, 1u);
}

TEST(KeyframeStore, OpenReadsNoScanAndRebuildsCopiesWhenAsked) {
  test::TempDir dir;
  const std::vector<PointCloud> scans = distinctScans(5);
  {
    KeyframeStore store = KeyframeStore::create(dir.path(), {.registration_voxel_m = 0.4});
    for (std::size_t k = 0; k < scans.size(); ++k)
      store.add(100.0 + static_cast<double>(k), somePose(static_cast<double>(k)), scans[k]);
    store.writePoses();
  }
  const KeyframeStore reopened = KeyframeStore::open(
      dir.path(), {.registration_voxel_m = 0.4, .registration_cache_keyframes = 2});
  EXPECT_EQ(reopened.registrationCacheStatistics().cached_keyframes, 0u);
  EXPECT_EQ(reopened.registrationCacheStatistics().rebuilt, 0u);
  for (std::uint64_t k : {4u, 0u, 2u, 3u, 0u, 1u, 1u}) {
    EXPECT_EQ(reopened.registrationCloud(k)->positions, expectedRegistrationPositions(scans[k]));
    EXPECT_LE(reopened.registrationCacheStatistics().cached_keyframes, 2u);
  }
  EXPECT_EQ(reopened.registrationCacheStatistics().rebuilt, 6u);  // 0 again: evicted by 2 and 3
  EXPECT_EQ(reopened.registrationCacheStatistics().hits, 1u);     // 1 again: still cached
}

TEST(KeyframeStore, ReadersGetExactCopiesWhileOneThreadAdds) {
  test::TempDir dir;
  constexpr std::size_t kKeyframes = 40;
  const std::vector<PointCloud> scans = distinctScans(kKeyframes);
  std::vector<std::vector<Eigen::Vector3d>> expected;
  for (const PointCloud& scan : scans) expected.push_back(expectedRegistrationPositions(scan));
  KeyframeStore store =
      KeyframeStore::create(dir.path(), {.registration_voxel_m = 0.4, .registration_cache_keyframes = 4});
  std::atomic<bool> adding_done = false;
  std::atomic<int> mismatches = 0;
  std::atomic<int> reads = 0;
  auto read_random_keyframes = [&](unsigned seed) {
    std::mt19937 rng(seed);
    while (!adding_done || reads < 200) {
      const std::size_t available = store.size();
      if (available == 0) continue;
      const std::uint64_t id = std::uniform_int_distribution<std::uint64_t>(0, available - 1)(rng);
      if (store.registrationCloud(id)->positions != expected[id]) ++mismatches;
      if (store.registrationCacheStatistics().cached_keyframes > 4) ++mismatches;
      ++reads;
    }
  };
  std::thread reader_a(read_random_keyframes, 1u), reader_b(read_random_keyframes, 2u);
  for (std::size_t k = 0; k < kKeyframes; ++k)
    store.add(100.0 + static_cast<double>(k), somePose(static_cast<double>(k)), scans[k]);
  adding_done = true;
  reader_a.join();
  reader_b.join();
  EXPECT_EQ(mismatches, 0);
  EXPECT_GE(reads, 200);
  EXPECT_LE(store.registrationCacheStatistics().cached_keyframes, 4u);
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
