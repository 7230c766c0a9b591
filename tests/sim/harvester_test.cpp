// The harvester rig: its motion on the strip road, its IMU, and its own cabin and crane in the
// scans together with the per-scan crop boxes of machine_boxes.csv.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/machine.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::sim {
namespace {

Motion makeHarvester(double duration_s, MotionParams params = scenarioByName("harvester").motion) {
  return Motion(params, duration_s, 3, Terrain(scenarioByName("harvester").forest, 3));
}

TEST(HarvesterMotion, StaysOnTheRoadAndStopsForTheConfiguredTimes) {
  MotionParams params = scenarioByName("harvester").motion;
  params.harvester_reverse_probability = 1.0;  // back up after every tree
  const Motion motion = makeHarvester(400.0, params);
  const Terrain terrain(scenarioByName("harvester").forest, 3);
  const auto stops = motion.standStills();
  int trees = 0, manoeuvres = 0;
  for (const StandStill& stop : stops) {
    if (stop.start_s > 400.0) break;
    SCOPED_TRACE(stop.start_s);
    const Eigen::Vector3d p0 = motion.at(stop.start_s).T_world_body.translation();
    if (stop.kind == StandStill::Kind::kTreeHandling) {
      ++trees;
      EXPECT_GE(stop.end_s - stop.start_s, params.harvester_stop_min_s);
      EXPECT_LE(stop.end_s - stop.start_s, params.harvester_stop_max_s);
    } else {
      ++manoeuvres;
      // It came backwards: before the stop, it was further along the road.
      EXPECT_GT(motion.at(stop.start_s - params.harvester_ramp_s - 0.5).T_world_body.translation().x(),
                p0.x() + 0.3);
    }
    // Standing still (up to the vibration, millimetres), but moving before and after.
    for (double t = stop.start_s; t <= stop.end_s; t += 0.1)
      EXPECT_LT((motion.at(t).T_world_body.translation() - p0).norm(), 0.01);
    EXPECT_GT((motion.at(stop.start_s - params.harvester_ramp_s).T_world_body.translation() - p0).norm(),
              0.25);
    EXPECT_GT((motion.at(stop.end_s + params.harvester_ramp_s).T_world_body.translation() -
               motion.at(stop.end_s).T_world_body.translation()).norm(),
              0.25);
  }
  EXPECT_GE(trees, 5);
  EXPECT_GE(manoeuvres, trees - 1);  // the last one may come after the end

  // On the road, at harvester speeds, with the sensor on the cabin roof; progress along x.
  double max_speed = 0.0;
  for (double t = 0.0; t < 400.0; t += 0.1) {
    const MotionState s = motion.at(t);
    const Eigen::Vector3d p = s.T_world_body.translation();
    ASSERT_LT(std::abs(p.y()), 2.5 - 1.0) << t;  // road half width 2.5 m, the machine ~1.4 m
    const double height = p.z() - terrain.smoothHeight(p.x(), p.y());
    // 3.8 m along the machine's up axis, which leans with the slope under the bogies
    ASSERT_GT(height, 3.4) << t;
    ASSERT_LT(height, 4.2) << t;
    max_speed = std::max(max_speed, s.v_world.head<2>().norm());
  }
  EXPECT_LT(max_speed, params.harvester_speed_max_mps + 0.1);
  EXPECT_GT(max_speed, params.harvester_speed_min_mps);
  EXPECT_GT(motion.at(400.0).T_world_body.translation().x(), 20.0);
}

TEST(HarvesterMotion, ShakesInBurstsWhileATreeIsHandled) {
  const Motion motion = makeHarvester(200.0);
  double shaking_acc = 0.0, shaking_rate = 0.0, driving_acc = 0.0;
  for (const StandStill& stop : motion.standStills()) {
    if (stop.kind != StandStill::Kind::kTreeHandling || stop.end_s > 200.0) continue;
    for (double t = stop.start_s; t < stop.end_s; t += 0.002) {
      const MotionState s = motion.at(t);
      shaking_acc = std::max(shaking_acc, s.a_world.norm());
      shaking_rate = std::max(shaking_rate, s.omega_body.norm());
    }
    for (double t = stop.end_s + 0.5; t < stop.end_s + 6.0; t += 0.002)
      driving_acc = std::max(driving_acc, motion.at(t).a_world.norm());
  }
  EXPECT_GT(shaking_acc, 3.0);  // several m/s^2
  EXPECT_LT(shaking_acc, 15.0);
  EXPECT_GT(shaking_rate, 2.0 * kRadPerDeg);  // some deg/s
  EXPECT_LT(shaking_rate, 15.0 * kRadPerDeg);
  EXPECT_LT(driving_acc, 1.0);
}

/// Integrates noiseless IMU samples from the true state at samples[first]; largest position error.
double integrationError(const Motion& motion, const std::vector<ImuSample>& samples, std::size_t first) {
  const Eigen::Vector3d g(0, 0, -9.81);
  const MotionState s0 = motion.at(samples[first].t_s);
  lie::SO3 R = s0.T_world_body.rotation();
  Eigen::Vector3d p = s0.T_world_body.translation(), v = s0.v_world;
  double max_error = 0.0;
  for (std::size_t k = first; k + 1 < samples.size(); ++k) {
    const double dt = samples[k + 1].t_s - samples[k].t_s;
    const Eigen::Vector3d a0 = R * samples[k].acceleration_imu_mps2 + g;
    R = R * lie::SO3::Exp(0.5 * (samples[k].angular_velocity_imu_radps +
                                 samples[k + 1].angular_velocity_imu_radps) * dt);
    const Eigen::Vector3d a1 = R * samples[k + 1].acceleration_imu_mps2 + g;
    p += v * dt + (a0 / 3.0 + a1 / 6.0) * dt * dt;
    v += 0.5 * (a0 + a1) * dt;
    max_error = std::max(max_error, (p - motion.at(samples[k + 1].t_s).T_world_body.translation()).norm());
  }
  return max_error;
}

TEST(HarvesterMotion, NoiselessImuIntegratesThroughVibrationBursts) {
  const Motion motion = makeHarvester(120.0);
  StandStill stop;
  for (const StandStill& s : motion.standStills())
    if (s.kind == StandStill::Kind::kTreeHandling) { stop = s; break; }
  ASSERT_GT(stop.end_s, 0.0);
  ImuParams params;
  params.noise = false;
  params.rate_hz = 5000.0;  // fine steps: the bursts reach 30 Hz
  ImuSimulator imu(params, 1);
  std::vector<ImuSample> samples;
  std::size_t first = 0;
  while (imu.nextTime_s() <= stop.end_s + 3.0) {
    if (imu.nextTime_s() < stop.start_s - 3.0) first = samples.size() + 1;
    samples.push_back(imu.next(motion));
  }
  EXPECT_LT(integrationError(motion, samples, first), 0.01);  // through the stop, drive on
}

/// machine_boxes.csv rows by scan stamp.
std::map<double, std::vector<OrientedBox>> readMachineBoxes(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz");
  std::map<double, std::vector<OrientedBox>> boxes;
  while (std::getline(in, line)) {
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    double stamp, id, v[10];
    row >> stamp >> id;
    for (double& x : v) row >> x;
    OrientedBox b;
    b.center = Eigen::Vector3d(v[0], v[1], v[2]);
    b.half_extents = Eigen::Vector3d(v[3], v[4], v[5]);
    b.orientation = Eigen::Quaterniond(v[6], v[7], v[8], v[9]).normalized();
    EXPECT_EQ(static_cast<std::size_t>(id), boxes[stamp].size());
    boxes[stamp].push_back(b);
  }
  return boxes;
}

TEST(HarvesterMachine, EveryMachineReturnLiesInsideItsScanBoxes) {
  Scenario scenario = scenarioByName("harvester");
  scenario.lidar.beams = 64;
  scenario.lidar.columns = 512;
  scenario.motion.harvester_drive_min_m = scenario.motion.harvester_drive_max_m = 3.0;
  scenario.motion.harvester_speed_min_mps = scenario.motion.harvester_speed_max_mps = 1.0;
  // 3 s standing, 3 m drive until 6 s, the crane out from 7 s, fully out at 11 s.
  const Simulation simulation(scenario, 12.0, 5);
  test::TempDir dir;
  writeSimulation(simulation, dir.path());
  const auto boxes = readMachineBoxes(dir.path() / "machine_boxes.csv");
  ASSERT_EQ(boxes.size(), 120u);
  const HarvesterMachine& machine = *simulation.motion().machine();

  SystemConfig config;
  io::readConfigYaml(dir.path() / "rig.yaml", config);
  io::Recording recording = io::openRecording(dir.path() / "recording.bag", config.recording, config.rig);
  std::size_t machine_points = 0, crane_points = 0, outside = 0, forest_points = 0,
              forest_inside = 0, imu = 0;
  double first_imu = 0.0, last_imu = 0.0;
  while (auto event = recording.next()) {
    if (const auto* sample = std::get_if<ImuSample>(&*event)) {
      (imu++ == 0 ? first_imu : last_imu) = sample->t_s;
      continue;
    }
    const auto* scan = std::get_if<io::Scan>(&*event);
    if (!scan) continue;
    auto it = boxes.lower_bound(scan->t_start_s - 1e-4);  // doubles near 1.7e9 s: 2.4e-7 s steps
    ASSERT_TRUE(it != boxes.end() && std::abs(it->first - scan->t_start_s) < 1e-4)
        << std::setprecision(17) << scan->t_start_s;
    const PointCloud& cloud = scan->cloud_in_lidar;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3d p_body = config.rig.T_body_lidar * cloud.positions[i];
      // A machine return: on a true machine surface at the point's firing time (+- range noise).
      const auto truth = machine.boxesInBody(cloud.times_s[i] - kRecordingEpoch_s);
      int on_machine = -1;
      for (std::size_t id = 0; id < truth.size(); ++id)
        if (truth[id].contains(p_body, 0.05)) on_machine = static_cast<int>(id);
      bool in_scan_box = false;
      for (const OrientedBox& b : it->second) in_scan_box |= b.contains(p_body, 1e-4);
      if (on_machine >= 0) {
        ++machine_points;
        crane_points += on_machine != HarvesterMachine::kCabin ? 1 : 0;
        outside += in_scan_box ? 0 : 1;
      } else {
        ++forest_points;
        forest_inside += in_scan_box ? 1 : 0;
      }
    }
  }
  EXPECT_NEAR((imu - 1) / (last_imu - first_imu), 500.0, 0.5);
  EXPECT_EQ(outside, 0u) << "of " << machine_points << " machine returns";
  EXPECT_GT(machine_points, forest_points / 50);  // the machine is a visible part of the scans
  EXPECT_GT(crane_points, 2000u);                 // the crane among them
  EXPECT_LT(forest_inside, forest_points / 50) << forest_inside << " of " << forest_points;

  // The fixed cabin box is in rig.yaml as a comment, the crane moves between scans.
  std::ifstream rig(dir.path() / "rig.yaml");
  const std::string rig_text((std::istreambuf_iterator<char>(rig)), std::istreambuf_iterator<char>());
  EXPECT_NE(rig_text.find("# Harvester: the cabin is a fixed box"), std::string::npos);
  const auto& early = boxes.begin()->second;
  const auto& late = boxes.rbegin()->second;
  EXPECT_LT((early[0].center - late[0].center).norm(), 1e-9);
  EXPECT_GT((early[HarvesterMachine::kHead].center - late[HarvesterMachine::kHead].center).norm(), 2.0);
}

TEST(HarvesterMachine, RaysHitTheNearestBoxFace) {
  std::vector<OrientedBox> boxes(1);
  boxes[0].center = Eigen::Vector3d(5, 0, 0);
  boxes[0].half_extents = Eigen::Vector3d(1, 2, 3);
  boxes[0].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const lie::SE3 T_world_body(lie::SO3(), Eigen::Vector3d(0, 0, 10));
  const MachineSnapshot snapshot(boxes, T_world_body);
  const Eigen::Vector3d origin(0, 0, 10);
  std::optional<RayHit> hit;
  snapshot.occlude(origin, Eigen::Vector3d::UnitX(), 50.0, hit);
  ASSERT_TRUE(hit);
  // The face x' = -1 of the box turned by 0.3 rad: along the x axis at 5 - 1 / cos(0.3).
  EXPECT_NEAR(hit->range_m, 5.0 - 1.0 / std::cos(0.3), 1e-12);
  EXPECT_NEAR(hit->normal_world.x(), -std::cos(0.3), 1e-12);
  EXPECT_EQ(hit->material, Material::kMachine);
  // A nearer forest hit wins; a ray that passes by does not change anything.
  std::optional<RayHit> forest = RayHit{2.0, Eigen::Vector3d::UnitX(), Material::kBark};
  snapshot.occlude(origin, Eigen::Vector3d::UnitX(), 50.0, forest);
  EXPECT_EQ(forest->material, Material::kBark);
  std::optional<RayHit> none;
  snapshot.occlude(origin, Eigen::Vector3d::UnitY(), 50.0, none);
  EXPECT_FALSE(none);
  snapshot.occlude(origin, -Eigen::Vector3d::UnitX(), 50.0, none);
  EXPECT_FALSE(none);
}

}  // namespace
}  // namespace taiga::sim
