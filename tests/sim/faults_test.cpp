// Faults injected into a simulated recording (scenario section `faults`, docs/simulator.md
// "Faults"): an IMU gap, a burst of lost packets, a scan from another place and an open field,
// each where it was asked for and nowhere else.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/temp_dir.hpp"
#include "simulate_and_read.hpp"

namespace taiga::sim {
namespace {

constexpr const char* kSmall = "lidar: {beams: 16, columns: 512}\n";

TEST(Faults, OffByDefault) {
  const Scenario s = scenarioByName("mixed");
  EXPECT_EQ(s.faults.imu_gap_s, 0.0);
  EXPECT_EQ(s.faults.packet_burst_scans, 0);
  EXPECT_EQ(s.faults.splice_at_s, 0.0);
}

TEST(Faults, EachWhereItWasAskedFor) {
  test::TempDir clean_dir, fault_dir;
  const Written clean = simulateAndRead(kSmall, clean_dir, 3.0);
  const Written faulty = simulateAndRead(
      std::string(kSmall) +
          "faults: {imu_gap_start_s: 1.0, imu_gap_s: 0.5, packet_burst_start_s: 1.5, "
          "packet_burst_scans: 3, packet_burst_loss: 0.9, splice_at_s: 2.5, splice_from_s: 0.5}\n",
      fault_dir, 3.0);
  ASSERT_EQ(clean.scans.size(), faulty.scans.size());

  // The IMU gap: 0.5 s of samples missing (the epoch is the first stamp's), the rest unchanged.
  const double t0_s = clean.imu_stamps_s.front();
  std::size_t in_gap = 0;
  for (double t : clean.imu_stamps_s) in_gap += (t - t0_s >= 1.0 - 1e-6 && t - t0_s < 1.5) ? 1 : 0;
  EXPECT_GT(in_gap, 90u);  // 200 Hz
  EXPECT_EQ(faulty.imu_samples, clean.imu_samples - in_gap);
  for (double t : faulty.imu_stamps_s) EXPECT_FALSE(t - t0_s > 1.0 + 1e-6 && t - t0_s < 1.5 - 1e-6);

  const double scan0_s = clean.scans.front().t_start_s;
  for (std::size_t k = 0; k < clean.scans.size(); ++k) {
    const io::Scan& c = clean.scans[k];
    const io::Scan& f = faulty.scans[k];
    const double t_s = c.t_start_s - scan0_s;
    const std::size_t n_clean = c.cloud_in_lidar.size(), n_fault = f.cloud_in_lidar.size();
    if (t_s > 1.45 && t_s < 1.75) {  // the burst: about 10 % of 32 packets left
      EXPECT_LT(n_fault, n_clean / 3) << "scan " << k;
    } else if (std::abs(t_s - 2.5) < 0.05) {  // the splice: the scan from 0.5 s, stamped now
      const io::Scan& from = clean.scans[5];
      ASSERT_EQ(n_fault, from.cloud_in_lidar.size());
      EXPECT_EQ(f.cloud_in_lidar.positions[n_fault / 2],
                from.cloud_in_lidar.positions[n_fault / 2]);
      EXPECT_NEAR(f.cloud_in_lidar.times_s.front() - f.t_start_s,
                  from.cloud_in_lidar.times_s.front() - from.t_start_s, 1e-6);
    } else {
      EXPECT_EQ(n_fault, n_clean) << "scan " << k;
      EXPECT_DOUBLE_EQ(c.t_start_s, f.t_start_s);
    }
  }
}

// The open field: the scans in the window keep only returns within 0.3 m of the terrain (checked
// against the same simulation's truth), a subset of the clean scan's points; the others are
// unchanged.
TEST(Faults, AnOpenFieldKeepsOnlyTheGround) {
  test::TempDir dir;
  const Written clean = simulateAndRead(kSmall, dir, 2.0);
  Scenario scenario;
  const Written faulty = simulateAndRead(
      std::string(kSmall) + "faults: {open_field_start_s: 0.5, open_field_s: 0.5}\n", dir, 2.0,
      &scenario);
  const Simulation truth(scenario, 2.0, 6);  // the seed of simulateAndRead
  const lie::SE3 T_body_lidar = truth.lidar().T_body_lidar();
  ASSERT_EQ(clean.scans.size(), faulty.scans.size());
  const double scan0_s = clean.scans.front().t_start_s;
  int open_scans = 0;
  for (std::size_t k = 0; k < clean.scans.size(); ++k) {
    const PointCloud& c = clean.scans[k].cloud_in_lidar;
    const PointCloud& f = faulty.scans[k].cloud_in_lidar;
    const double t_s = clean.scans[k].t_start_s - scan0_s;
    if (t_s < 0.45 || t_s > 0.95) {
      EXPECT_EQ(f.size(), c.size()) << "scan " << k;
      continue;
    }
    ++open_scans;
    EXPECT_LT(f.size(), c.size() * 9 / 10) << "scan " << k;  // the stems and crowns are gone
    EXPECT_GT(f.size(), c.size() / 10) << "scan " << k;     // the ground is not
    std::size_t checked = 0;
    for (std::size_t i = 0; i < f.size(); i += 50, ++checked) {
      const double t_motion_s = f.times_s[i] - kRecordingEpoch_s;
      const Eigen::Vector3d p =
          truth.motion().at(t_motion_s).T_world_body * T_body_lidar * f.positions[i];
      EXPECT_LE(p.z() - truth.scene().terrain().height(p.x(), p.y()), 0.3 + 1e-6) << "scan " << k;
      EXPECT_NE(std::find(c.positions.begin(), c.positions.end(), f.positions[i]),
                c.positions.end());
    }
    EXPECT_GT(checked, 10u);
  }
  EXPECT_EQ(open_scans, 5);  // 0.5 s at 10 Hz
}

}  // namespace
}  // namespace taiga::sim
