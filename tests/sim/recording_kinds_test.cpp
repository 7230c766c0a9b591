// The kinds of recordings users have, from the simulator: a Velodyne-like head with its driver's
// layout, clouds deskewed upstream without a time field, and low-rate scan sequences without an
// IMU (docs/simulator.md, "Kinds of recordings").
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "../support/temp_dir.hpp"
#include "simulate_and_read.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

/// Median distance of the scan's points to the true scene when each point is placed with
/// `T_world_lidar(point time)`.
template <class PoseAt>
double medianSurfaceDistance(const Simulation& sim, const io::Scan& scan, PoseAt T_world_lidar) {
  std::vector<double> d;
  const PointCloud& c = scan.cloud_in_lidar;
  for (std::size_t i = 0; i < c.size(); i += 7)
    d.push_back(sim.scene().distanceToSurface(T_world_lidar(c.times_s[i]) * c.positions[i], 1.0));
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

TEST(RecordingKinds, VelodyneHeadWithItsDriversLayout) {
  test::TempDir dir;
  const Written w = simulateAndRead(
      "lidar: {model: vlp-16, columns: 1800}\noutput: {point_layout: velodyne}\n", dir, 0.5);
  ASSERT_EQ(w.scans.size(), 5u);
  for (const io::Scan& scan : w.scans) {
    const PointCloud& c = scan.cloud_in_lidar;
    EXPECT_GT(c.size(), 10000u);  // of 16 x 1800
    EXPECT_LE(c.size(), 16u * 1800u);
    ASSERT_TRUE(c.hasRings());
    EXPECT_LT(*std::max_element(c.rings.begin(), c.rings.end()), 16);
    const auto [t0, t1] = c.timeSpan();
    EXPECT_GE(t0, scan.t_start_s - 1e-6);  // the driver's 'time' field, not invented
    EXPECT_NEAR(t1 - t0, 0.1, 0.002);
  }
}

TEST(RecordingKinds, DeskewedLowRateScansWithoutImu) {
  test::TempDir dir;
  Scenario s;
  const Written w = simulateAndRead(
      "lidar: {beams: 32, columns: 512}\n"
      "output: {point_layout: deskewed, scan_stride: 5, imu: false, gnss: false}\n",
      dir, 2.0, &s);
  EXPECT_EQ(w.imu_samples, 0u);
  EXPECT_TRUE(w.rig.recording.imu_topic.empty());
  ASSERT_EQ(w.scans.size(), 4u);  // scans 0, 5, 10, 15 of 20: 2 Hz
  EXPECT_NEAR(w.scans[1].t_start_s - w.scans[0].t_start_s, 0.5, 1e-6);
  // Every point lies on the scene when placed with the single pose at the header stamp: the
  // cloud was deskewed with the true motion. (The reader invents times over a sweep; they are
  // ignored here.)
  const Simulation sim(s, 2.0, 6);
  const lie::SE3 T_body_lidar = sim.lidar().T_body_lidar();
  for (const io::Scan& scan : w.scans) {
    const lie::SE3 T_world_lidar_start =
        sim.motion().at(scan.t_start_s - kRecordingEpoch_s).T_world_body * T_body_lidar;
    EXPECT_LT(medianSurfaceDistance(sim, scan, [&](double) { return T_world_lidar_start; }), 0.02);
  }
  // The same scan as the sensor delivered it, placed with one pose, is skewed by the motion:
  // the test can tell a deskewed cloud from a raw one.
  const io::Scan raw = sim.lidar().simulateScan(sim.scene(), sim.motion(), 15, 1.5);
  const lie::SE3 T_world_lidar_raw = sim.motion().at(1.5).T_world_body * T_body_lidar;
  EXPECT_GT(medianSurfaceDistance(sim, raw, [&](double) { return T_world_lidar_raw; }), 0.03);
}

}  // namespace
}  // namespace taiga::sim
