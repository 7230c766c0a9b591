// `taiga run` with mapping.gnss_fusion on, as users run it: the fixes reach the mapping graph,
// summary.json reports the graph's T_enu_map, which with exact fixes puts the trajectory onto
// the truth, and a second run gives the same bytes (the mapping thread's timing does not matter).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga {
namespace {

using test::runTaiga;

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

TEST(GnssFusionCli, TaigaRunFusesTheFixesAndReportsTheMapToEnuTransform) {
  test::TempDir dir;
  // Exact fixes and a world turned 30 deg from east: the fused transform must find the turn.
  // The beam table of a real OS0-128 unit (the bounds below were measured with it): with the
  // built-in nominal table the same 16-beam walk gives 0.148 m RMS and 0.52 m worst, although
  // its odometry alone is better (2.4 vs 3.3 cm APE) - the fusion's start-up is sensitive.
  const auto overrides = dir.write(
      "exact.yaml",
      "gnss: {noise: false, world_yaw_deg: 30}\n"
      "lidar: {metadata_json: ../shared/data/ouster/OS-0-128-U1_v2.3.0_1024x10.json}\n");
  const auto sim = dir.file("sim");
  ASSERT_EQ(runTaiga("simulate --scenario handheld-loop --duration 30 --beams 16 --columns 512 "
                     "--sub-rays 1 --seed 5 --overrides " +
                     overrides.string() + " --out " + sim.string())
                .exit_code,
            0);
  std::string rig = readText(sim / "rig.yaml");
  const auto at = rig.find("gnss_fusion: false");
  ASSERT_NE(at, std::string::npos) << "rig.yaml lists mapping.gnss_fusion";
  rig.replace(at, std::string("gnss_fusion: false").size(), "gnss_fusion: true");
  // The first 30 s of the walk stay within 10 m of the start: start fusing at 5 m.
  const auto spread = rig.find("gnss_min_spread_m: 10");
  ASSERT_NE(spread, std::string::npos);
  rig.replace(spread, std::string("gnss_min_spread_m: 10").size(), "gnss_min_spread_m: 5");
  const auto config = dir.write("fused.yaml", rig);

  auto runInto = [&](const std::string& name) {
    const auto out = dir.file(name);
    const test::TaigaResult r = runTaiga("run " + (sim / "recording.bag").string() + " --config " +
                                         config.string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return out;
  };
  const auto run = runInto("run");
  const auto summary = nlohmann::json::parse(readText(run / "summary.json"));
  ASSERT_TRUE(summary.contains("gnss_fusion")) << summary.dump(2);
  const auto& fusion = summary["gnss_fusion"];
  EXPECT_GE(fusion["used"].get<int>(), 20) << fusion.dump(2);
  EXPECT_EQ(fusion["gated"].get<int>(), 0);
  ASSERT_TRUE(fusion.contains("T_enu_map")) << fusion.dump(2);

  // The graph's T_enu_map, with exact fixes, takes the run's trajectory onto the truth in the
  // ENU frame at the fusion's origin, to within the odometry's error.
  Eigen::Matrix4d T_enu_map;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) T_enu_map(i, j) = fusion["T_enu_map"][i][j].get<double>();
  const geo::Geodetic fusion_origin{fusion["enu_origin"]["latitude_deg"].get<double>(),
                                    fusion["enu_origin"]["longitude_deg"].get<double>(),
                                    fusion["enu_origin"]["height_ellipsoid_m"].get<double>()};
  const geo::Geodetic sim_origin{61.0, 24.5, 120.0};  // the handheld-loop scenario's
  const double world_yaw_rad = 30.0 * kRadPerDeg;
  Eigen::Matrix3d R_enu_simworld;
  R_enu_simworld << std::cos(world_yaw_rad), -std::sin(world_yaw_rad), 0, std::sin(world_yaw_rad),
      std::cos(world_yaw_rad), 0, 0, 0, 1;
  const geo::CoordinateConverter converter;
  const Trajectory truth = io::readTum(sim / "groundtruth.tum");
  const Trajectory estimate = io::readTum(run / "trajectory.tum");
  double worst_horizontal_m = 0.0, sum_squared_m2 = 0.0;
  std::size_t compared = 0;
  for (const StampedPose& pose : estimate) {
    const auto T_simworld_body = truth.tryPoseAt(pose.t_s);
    if (!T_simworld_body) continue;
    const Eigen::Vector3d p_truth = converter.toEnu(
        fusion_origin,
        converter.fromEnu(sim_origin, R_enu_simworld * T_simworld_body->translation()));
    const Eigen::Vector3d p_fused = (T_enu_map * pose.pose.translation().homogeneous()).head<3>();
    worst_horizontal_m = std::max(worst_horizontal_m, (p_fused - p_truth).head<2>().norm());
    sum_squared_m2 += (p_fused - p_truth).squaredNorm();
    ++compared;
  }
  EXPECT_GT(compared, 200u);
  // Measured: 3D RMS 0.055 m; the worst (0.35 m) is the first keyframe, which holds the gauge at
  // the odometry's start-up pose and so is not corrected.
  const double rms_m = std::sqrt(sum_squared_m2 / static_cast<double>(compared));
  EXPECT_LT(rms_m, 0.15);
  EXPECT_LT(worst_horizontal_m, 0.5);
  RecordProperty("rms_m", std::to_string(rms_m));
  RecordProperty("worst_horizontal_m", std::to_string(worst_horizontal_m));

  // The same run again: the same bytes.
  const auto again = runInto("again");
  EXPECT_EQ(readText(again / "trajectory.tum"), readText(run / "trajectory.tum"));
  EXPECT_EQ(readText(again / "keyframes.tum"), readText(run / "keyframes.tum"));
  EXPECT_EQ(nlohmann::json::parse(readText(again / "summary.json"))["gnss_fusion"], fusion);
}

}  // namespace
}  // namespace taiga
