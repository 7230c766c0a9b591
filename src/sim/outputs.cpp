#include "outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "machine_boxes_output.hpp"
#include "truth_outputs.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim::detail {
namespace {
/// The errors of the true rig beyond what its configuration holds.
std::string trueRigComment(const Scenario& s) {
  const ImuParams& imu = s.imu;
  return fmt::format(
      "# Realism '{}': true IMU noise densities {}x and bias walks {}x the stated ones (below);\n"
      "#   Gauss-Markov biases {} m/s^2 and {} rad/s (1-sigma, {} s); scale errors {} and axis\n"
      "#   misalignments {} deg (1-sigma; the gyro's drawn ones are rig.gyro_axes below, the\n"
      "#   accelerometer's are not in the rig); gyro g-sensitivity {} deg/s/g; clipping at {} g\n"
      "#   and {} deg/s (0: none); stamp jitter {} s; lidar clock drift {} ppm (the offset below\n"
      "#   holds at the start); extrinsic error {} deg and {} m; lidar: range noise at the limit\n"
      "#   {} m, dropouts {}, packet loss {}; wind sway {} m at 20 m.\n",
      s.realism, imu.noise_density_factor, imu.bias_walk_factor, imu.accel_bias_instability_mps2,
      imu.gyro_bias_instability_radps, imu.bias_correlation_s, imu.scale_factor_error,
      imu.misalignment_deg, imu.gyro_g_sensitivity_deg_s_per_g, imu.accel_range_g,
      imu.gyro_range_deg_s, imu.timestamp_jitter_s, s.rig.lidar_clock_drift_ppm,
      s.rig.extrinsic_rotation_error_deg, s.rig.extrinsic_translation_error_m,
      s.lidar.range_noise_at_limit_m, s.lidar.dropout_probability,
      s.lidar.packet_loss_probability, s.forest.wind_sway_m);
}

lie::SE3 statedTBodyLidar(const Simulation& simulation) {
  const RigErrorParams& error = simulation.scenario().rig;
  const lie::SE3 T_body_lidar = simulation.lidar().T_body_lidar();
  if (error.extrinsic_rotation_error_deg <= 0.0 && error.extrinsic_translation_error_m <= 0.0)
    return T_body_lidar;
  // Fixed magnitudes, directions drawn from the seed: T_stated = T_true * Exp(error).
  const std::uint64_t seed = streamSeed(simulation.seed(), "rig");
  auto direction = [&](std::uint64_t stream) {
    return Eigen::Vector3d(hashNormal(seed, stream, 0), hashNormal(seed, stream, 1),
                           hashNormal(seed, stream, 2))
        .normalized();
  };
  const lie::SE3 error_lidar(
      lie::SO3::Exp(error.extrinsic_rotation_error_deg * kRadPerDeg * direction(1)),
      error.extrinsic_translation_error_m * direction(2));
  return T_body_lidar * error_lidar;
}
}  // namespace

void writeRigYaml(const std::filesystem::path& path, const Simulation& simulation, RigView view) {
  const bool truth = view == RigView::kTrue;
  const ImuParams& imu = simulation.scenario().imu;
  const RigErrorParams& rig_error = simulation.scenario().rig;
  SystemConfig config;
  config.rig.T_body_lidar =
      truth ? simulation.lidar().T_body_lidar() : statedTBodyLidar(simulation);
  config.rig.T_body_imu = lie::SE3();
  config.rig.lidar_time_offset_s = truth ? rig_error.lidar_time_offset_s : 0.0;
  config.rig.imu_acceleration_unit = AccelerationUnit::kMetersPerSecond2;
  if (truth)
    config.rig.gyro_axes.M_reading_true =
        ImuSimulator(imu, simulation.seed(), simulation.scenario().gnss.world_yaw_deg).gyroAxes();
  config.recording.lidar_topic = kLidarTopic;
  const OutputParams& output = simulation.scenario().output;
  config.recording.imu_topic = output.imu ? kImuTopic : "";
  config.recording.gnss_topic = output.gnss ? kGnssTopic : "";
  config.recording.scan_period_s = simulation.lidar().scanPeriod_s();
  const double noise_factor = truth ? imu.noise_density_factor : 1.0;
  const double walk_factor = truth ? imu.bias_walk_factor : 1.0;
  config.odometry.imu.accel_noise_density = imu.accel_noise_density * noise_factor;
  config.odometry.imu.gyro_noise_density = imu.gyro_noise_density * noise_factor;
  config.odometry.imu.accel_bias_random_walk = imu.accel_bias_random_walk * walk_factor;
  config.odometry.imu.gyro_bias_random_walk = imu.gyro_bias_random_walk * walk_factor;
  config.odometry.imu.gravity_mps2 = imu.gravity_mps2;
  // A rig stated exactly needs no calibration at the start of a run (docs/calibration.md).
  const bool stated_exactly = rig_error.extrinsic_rotation_error_deg == 0.0 &&
                              rig_error.extrinsic_translation_error_m == 0.0 &&
                              rig_error.lidar_time_offset_s == 0.0 &&
                              rig_error.lidar_clock_drift_ppm == 0.0;
  config.calibration.at_start = !(truth || stated_exactly);
  // The true rig is exact at the start and stays the floor runs are compared with; a drifting
  // clock in a stated rig is for the run to follow (pipeline/clock_tracker.hpp).
  config.calibration.track_offset = config.calibration.at_start;
  if (!simulation.scenario().output.pcap_profile.empty())  // taiga run --live --config rig.yaml
    config.live.metadata = std::filesystem::absolute(path.parent_path() / "capture.json").string();
  if (simulation.lidar().rows() >= 64) {
    // Dense scans: the settings of config/os0-128-handheld.yaml (docs/odometry.md, "Scale").
    config.odometry.ndt_resolution_m = 0.5;
    config.odometry.local_map_keyframes = 16;
  }
  const LidarParams& lidar = simulation.scenario().lidar;
  std::string header = fmt::format(
      "# Rig of a simulated recording (taiga simulate --scenario {} --seed {} --duration {}\n"
      "# --realism {}): {}.\n"
      "# Body = IMU frame; the lidar frame is the Ouster sensor frame (points as the Ouster ROS\n"
      "# driver publishes them). Beam geometry: {}.\n"
      "# Stated noise (datasheet; the IMU densities are also in odometry.imu below):\n"
      "#   IMU {} Hz: accelerometer noise {} m/s^2/sqrt(Hz), bias walk {} m/s^3/sqrt(Hz), turn-on "
      "{} m/s^2\n"
      "#              gyroscope noise {} rad/s/sqrt(Hz), bias walk {} rad/s^2/sqrt(Hz), turn-on {} "
      "rad/s\n"
      "#   lidar: range noise {} m + {} m per m, divergence {} deg\n",
      simulation.scenario().name, simulation.seed(), simulation.duration_s(),
      simulation.scenario().realism,
      truth ? "the true rig, as the simulator built it"
            : "as its user would write it (nominal extrinsics, datasheet noise, no time offset;\n"
              "# the truth is in rig_truth.yaml)",
      simulation.lidar().geometry().source, imu.rate_hz, imu.accel_noise_density,
      imu.accel_bias_random_walk, imu.accel_turn_on_bias, imu.gyro_noise_density,
      imu.gyro_bias_random_walk, imu.gyro_turn_on_bias, lidar.range_noise_m,
      lidar.range_noise_per_m, lidar.beam_divergence_deg);
  if (truth) header += trueRigComment(simulation.scenario());
  if (simulation.motion().machine()) {
    header += cabinBoxRigComment();
    const OrientedBox cabin = HarvesterMachine::cabinInBody();  // axis-aligned in the body frame
    const Eigen::Vector3d grown = cabin.half_extents.array() + kMachineBoxMargin_m;
    config.rig.self_boxes_body = {{cabin.center - grown, cabin.center + grown}};
  }
  writeText(path, header + io::writeConfigYaml(config));
}

void writeSceneJson(const std::filesystem::path& path, const Simulation& simulation,
                    const SimulationSummary& summary) {
  using nlohmann::json;
  const Scenario& s = simulation.scenario();
  const Scene& scene = simulation.scene();
  json j;
  j["scenario"] = s.name;
  j["realism"] = s.realism;
  j["seed"] = simulation.seed();
  j["duration_s"] = simulation.duration_s();
  j["time_epoch_s"] = kRecordingEpoch_s;
  j["world_frame"] = {
      {"description",
       "east-north-up at the origin below turned by world_yaw_deg about up, z up; "
       "groundtruth.tum holds T_world_body, georef_truth.yaml the frame in EPSG:3067"},
      {"world_yaw_deg", s.gnss.world_yaw_deg},
      {"origin_latitude_deg", s.gnss.origin_latitude_deg},
      {"origin_longitude_deg", s.gnss.origin_longitude_deg},
      {"origin_height_ellipsoid_m", s.gnss.origin_height_m},
      {"ellipsoid", "WGS84"}};
  const SceneLayout& layout = scene.layout();
  j["plot"] = {
      {"center_x_m", layout.center_world.x()}, {"center_y_m", layout.center_world.y()},
      {"half_size_m", layout.half_size_m},     {"area_ha", summary.scene.area_ha},
      {"triangles", summary.scene.triangles},  {"curve_segments", summary.scene.curve_segments}};
  j["forest"] = {
      {"stems_per_ha", s.forest.stems_per_ha},   {"dbh_mean_m", s.forest.dbh_mean_m},
      {"dbh_sigma_m", s.forest.dbh_sigma_m},     {"saplings_per_ha", s.forest.saplings_per_ha},
      {"shrubs_per_ha", s.forest.shrubs_per_ha}, {"boulders_per_ha", s.forest.boulders_per_ha},
      {"logs_per_ha", s.forest.logs_per_ha},     {"road_half_width_m", s.forest.road_half_width_m}};
  const LidarSimulator& lidar = simulation.lidar();
  j["lidar"] = {{"metadata", lidar.geometry().source},
                {"rows", lidar.rows()},
                {"columns", lidar.columns()},
                {"rotation_hz", s.lidar.rotation_hz},
                {"range_noise_m", s.lidar.range_noise_m},
                {"range_noise_per_m", s.lidar.range_noise_per_m},
                {"beam_divergence_deg", s.lidar.beam_divergence_deg},
                {"sub_rays", s.lidar.sub_rays},
                {"max_range_m", s.lidar.max_range_m},
                {"dropout_probability", s.lidar.dropout_probability}};
  j["imu"] = {{"rate_hz", s.imu.rate_hz},
              {"accel_noise_density", s.imu.accel_noise_density},
              {"gyro_noise_density", s.imu.gyro_noise_density},
              {"accel_bias_random_walk", s.imu.accel_bias_random_walk},
              {"gyro_bias_random_walk", s.imu.gyro_bias_random_walk},
              {"accel_turn_on_bias", s.imu.accel_turn_on_bias},
              {"gyro_turn_on_bias", s.imu.gyro_turn_on_bias},
              {"gravity_mps2", s.imu.gravity_mps2}};
  j["gnss"] = {{"rate_hz", s.gnss.rate_hz},
               {"sigma_open_horizontal_m", s.gnss.sigma_open_horizontal_m},
               {"sigma_canopy_horizontal_m", s.gnss.sigma_canopy_horizontal_m},
               {"reported_sigma_factor", s.gnss.reported_sigma_factor}};
  j["summary"] = {{"scans", summary.scans},
                  {"imu_samples", summary.imu_samples},
                  {"gnss_fixes", summary.gnss_fixes},
                  {"points", summary.points},
                  {"min_points_per_scan", summary.min_points_per_scan},
                  {"max_points_per_scan", summary.max_points_per_scan},
                  {"path_length_m", summary.path_length_m},
                  {"loop_period_s", simulation.motion().loopPeriod_s()}};
  json trees = json::array();
  for (const Tree& t : scene.trees()) {
    trees.push_back({{"x_m", t.base_world.x()},
                     {"y_m", t.base_world.y()},
                     {"z_m", t.base_world.z()},
                     {"dbh_m", t.dbh_m},
                     {"height_m", t.height_m},
                     {"lean_deg", t.lean_rad * kDegPerRad},
                     {"lean_azimuth_deg", t.lean_azimuth_rad * kDegPerRad},
                     {"crown_base_m", t.crown_base_m},
                     {"species", speciesName(t.species)}});
  }
  j["trees"] = std::move(trees);
  json boulders = json::array();
  for (const Boulder& b : scene.boulders()) {
    boulders.push_back({{"x_m", b.center_world.x()},
                        {"y_m", b.center_world.y()},
                        {"z_m", b.center_world.z()},
                        {"radius_m", b.radius_m}});
  }
  j["boulders"] = std::move(boulders);
  json logs = json::array();
  for (const FallenLog& l : scene.logs()) {
    logs.push_back({{"start_m", {l.start_world.x(), l.start_world.y(), l.start_world.z()}},
                    {"end_m", {l.end_world.x(), l.end_world.y(), l.end_world.z()}},
                    {"radius_m", l.radius_m}});
  }
  j["logs"] = std::move(logs);
  writeText(path, j.dump(1) + "\n");
}

}  // namespace taiga::sim::detail
