#pragma once
// The whole simulator: a scene, a walk through it, and the lidar, IMU and GNSS recording it, with
// the outputs of `taiga simulate` (see docs/simulator.md):
//   recording.bag      /os_cloud_node/points (Ouster PointCloud2, organized rows x columns),
//                      /imu/data (sensor_msgs/Imu), /gnss/fix (sensor_msgs/NavSatFix)
//   groundtruth.tum    T_world_body at the IMU rate (body = IMU frame)
//   rig.yaml           the configuration a user would write for this rig (nominal extrinsics,
//                      datasheet noise, no time offset)
//   rig_truth.yaml     the same keys with the true values (realism.hpp: equal to rig.yaml but
//                      for comments in the ideal preset)
//   scene.json         scenario, seed, georeference of the world frame, every stem's truth
//   trees.csv          one row per stem: base position, DBH, height, lean, species
//   georef_truth.yaml  the world frame in EPSG:3067 (origin, rotation, scale, T_epsg_world);
//                      written first: an unknown gnss.georef_epsg fails before the recording
//   scenario.yaml      the effective scenario (taiga simulate --overrides scenario.yaml redoes it)
//   reference_cloud.las  on request (reference_cloud.hpp): a dense noise-free TLS cloud

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "taiga/sim/gnss.hpp"
#include "taiga/sim/imu.hpp"
#include "taiga/sim/lidar.hpp"
#include "taiga/sim/motion.hpp"
#include "taiga/sim/scenario.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

/// Times written to files are motion time + this epoch (2023-11-14 22:13:20 UTC), because ROS
/// bags cannot store times at or near zero.
inline constexpr double kRecordingEpoch_s = 1700000000.0;

/// Topics and frame ids of the written bag.
inline constexpr const char* kLidarTopic = "/os_cloud_node/points";
inline constexpr const char* kImuTopic = "/imu/data";
inline constexpr const char* kGnssTopic = "/gnss/fix";

/// Scene, motion and sensors of one scenario, built once and shared by the outputs.
class Simulation {
 public:
  Simulation(const Scenario& scenario, double duration_s, std::uint64_t seed);

  const Scenario& scenario() const { return scenario_; }
  double duration_s() const { return duration_s_; }
  std::uint64_t seed() const { return seed_; }
  const Scene& scene() const { return *scene_; }
  const WalkingMotion& motion() const { return *motion_; }
  const LidarSimulator& lidar() const { return *lidar_; }
  /// Number of complete scans that fit in the duration.
  std::size_t scanCount() const;

 private:
  Scenario scenario_;
  double duration_s_;
  std::uint64_t seed_;
  std::unique_ptr<WalkingMotion> motion_;
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<LidarSimulator> lidar_;
};

struct SimulationSummary {
  std::size_t scans = 0;
  std::size_t imu_samples = 0;
  std::size_t gnss_fixes = 0;
  std::size_t points = 0;
  std::size_t min_points_per_scan = 0;
  std::size_t max_points_per_scan = 0;
  std::size_t trees = 0;
  SceneStats scene;
  double path_length_m = 0.0;
  double scene_build_s = 0.0;  ///< wall time to generate the scene
  double simulate_s = 0.0;     ///< wall time for the sensors and writing
};

/// Writes every output into `out_dir` (created if needed). `on_scan(done, total)` is called after
/// each scan, e.g. for a progress line.
SimulationSummary writeSimulation(
    const Simulation& simulation, const std::filesystem::path& out_dir,
    const std::function<void(std::size_t, std::size_t)>& on_scan = {});

}  // namespace taiga::sim
