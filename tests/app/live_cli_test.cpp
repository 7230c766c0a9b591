// Issue 24: `taiga simulate --pcap`, `taiga replay` and `taiga run --live` as users run them. A
// simulated capture replayed over loopback and processed live gives the same trajectory as the
// run on the capture file; SIGTERM ends a live run with every output written; bad setups get a
// clear error.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "../support/run_taiga.hpp"
#include "../support/simulated_capture.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/io/udp_socket.hpp"
#include "taiga/lie/so3.hpp"

namespace taiga::app {
namespace {

using ::testing::HasSubstr;

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Ports of this test process: Ouster's 7502/7503 moved by the offset given to `taiga replay`.
int portOffset() { return 30000 + (getpid() % 5000) * 4 - 7502; }

/// The simulated rig.yaml (whose live.metadata names the capture's JSON) receiving on this
/// process's ports.
std::filesystem::path liveConfig(const std::filesystem::path& sim, double idle_timeout_s) {
  YAML::Node config = YAML::LoadFile((sim / "rig.yaml").string());
  config["live"]["bind_address"] = "127.0.0.1";
  config["live"]["lidar_port"] = 7502 + portOffset();
  config["live"]["imu_port"] = 7503 + portOffset();
  config["live"]["idle_timeout_s"] = idle_timeout_s;
  config["live"]["max_queued_scans"] = 1000;  // a slow test machine lags, and drops nothing
  config["live"]["pose_udp"] = fmt::format("127.0.0.1:{}", 7504 + portOffset());
  const auto path = sim / fmt::format("live_{}.yaml", idle_timeout_s);
  std::ofstream(path) << config << "\n";
  return path;
}

/// The pose stream's datagrams (live.pose_udp), parsed, collected on a thread until stop().
class PoseReceiver {
 public:
  PoseReceiver()
      : socket_(io::UdpSocket::bound("127.0.0.1", static_cast<std::uint16_t>(7504 + portOffset()),
                                     8 << 20)),
        thread_([this] { receive(); }) {}
  std::vector<nlohmann::json> stop() {
    done_ = true;
    thread_.join();
    return poses_;
  }

 private:
  void receive() {
    const io::UdpSocket* sockets[] = {&socket_};
    std::vector<std::uint8_t> datagram;
    while (!done_) {
      io::waitReadable(sockets, std::chrono::milliseconds(50));
      while (socket_.receive(datagram)) poses_.push_back(nlohmann::json::parse(datagram));
    }
  }
  io::UdpSocket socket_;
  std::atomic<bool> done_{false};
  std::vector<nlohmann::json> poses_;
  std::thread thread_;
};

/// Rows "t x y z ..." of a TUM file by time (ns), positions only.
std::map<long long, Eigen::Vector3d> tumPositions(const std::filesystem::path& path) {
  std::map<long long, Eigen::Vector3d> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0.0;
    Eigen::Vector3d p;
    fields >> t >> p.x() >> p.y() >> p.z();
    rows[std::llround(t * 1e4)] = p;  // 0.1 ms keys: the stream prints t_s to the microsecond
  }
  return rows;
}

/// The turn that levelled a run's final outputs after the live ones went out (summary.json
/// frame_tilt_deg: R = Exp(-[theta; 0]), docs/frames.md).
lie::SO3 finalLevelling(const std::filesystem::path& run_dir) {
  const nlohmann::json summary = nlohmann::json::parse(readText(run_dir / "summary.json"));
  const Eigen::Vector3d tilt_rad(summary["frame_tilt_deg"][0].get<double>() * kRadPerDeg,
                                 summary["frame_tilt_deg"][1].get<double>() * kRadPerDeg, 0.0);
  return lie::SO3::Exp(-tilt_rad);
}

std::future<test::TaigaResult> startLive(const std::filesystem::path& config,
                                         const std::filesystem::path& out) {
  auto live = std::async(std::launch::async, [=] {
    return test::runTaiga("run --live --config " + config.string() + " --out " + out.string());
  });
  std::this_thread::sleep_for(std::chrono::seconds(1));  // until it listens
  return live;
}

TEST(LiveCli, AReplayedCaptureRunLiveGivesTheTrajectoryOfTheCaptureFile) {
  test::TempDir dir;
  const auto sim = test::simulateCapture(dir);
  // The file run on one worker thread, the live run on every core: the thread count changes no
  // output (the parallel sums add fixed blocks in a fixed order).
  const auto file_run = sim / "file_run";
  const test::TaigaResult file =
      test::runTaiga("run " + (sim / "capture.pcap").string() + " --config " +
                     (sim / "rig.yaml").string() + " --out " + file_run.string() + " --threads 1");
  ASSERT_EQ(file.exit_code, 0) << file.output;
  EXPECT_THAT(file.output, HasSubstr("per scan on 1 thread;"));
  EXPECT_EQ(nlohmann::json::parse(readText(file_run / "summary.json"))["threads"], 1);

  const auto live_run = sim / "live_run";
  PoseReceiver pose_receiver;
  auto live = startLive(liveConfig(sim, 3.0), live_run);
  const test::TaigaResult replay = test::runTaiga(fmt::format(
      "replay {} --rate 1 --port-offset {}", (sim / "capture.pcap").string(), portOffset()));
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const test::TaigaResult r = live.get();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("0 incomplete"));
  EXPECT_THAT(r.output, HasSubstr("0 scans dropped"));

  // Every packet arrived, so every scan and IMU sample is the file's: the same trajectory.
  const std::string expected = readText(file_run / "trajectory.tum");
  ASSERT_GT(expected.size(), 1000u);
  EXPECT_EQ(readText(live_run / "trajectory.tum"), expected);
  EXPECT_EQ(readText(live_run / "trajectory_imu.tum"), readText(file_run / "trajectory_imu.tum"));
  const nlohmann::json summary = nlohmann::json::parse(readText(live_run / "summary.json"));
  EXPECT_EQ(summary["live"]["frames"], 40);
  EXPECT_EQ(summary["live"]["missing_columns"], 0);
  EXPECT_THAT(summary["live"]["stop_reason"].get<std::string>(), HasSubstr("no packet"));

  // The pose stream: every published scan pose (trajectory_online.tum), and IMU-rate poses
  // dead-reckoned from the latest one as their packets arrived, near the run's IMU-rate poses
  // once levelled as those were at the end (summary.json frame_tilt_deg).
  const std::vector<nlohmann::json> poses = pose_receiver.stop();
  const lie::SO3 R_level_odom = finalLevelling(live_run);
  const auto online = tumPositions(live_run / "trajectory_online.tum");
  const auto imu_rate = tumPositions(live_run / "trajectory_imu.tum");
  std::size_t scans = 0, imu = 0, imu_fresh = 0, imu_fresh_near = 0, with_covariance = 0;
  for (const nlohmann::json& pose : poses) {
    const Eigen::Vector3d p(pose["p"][0], pose["p"][1], pose["p"][2]);
    const long long key = std::llround(pose["t_s"].get<double>() * 1e4);
    if (pose["type"] == "scan") {
      ++scans;
      ASSERT_TRUE(online.contains(key)) << pose.dump();
      EXPECT_LT((online.at(key) - p).norm(), 1e-3) << pose.dump();
      EXPECT_EQ(pose["status"], "ok");
      // The pose's covariance: millimetres to decimetres, tenths of degrees, symmetric.
      if (!pose.contains("cov")) continue;  // nothing measured the first scan's pose
      ++with_covariance;
      for (int i = 0; i < 3; ++i) {
        EXPECT_GT(pose["sigma_m"][i].get<double>(), 1e-4) << pose.dump();
        EXPECT_LT(pose["sigma_m"][i].get<double>(), 0.3) << pose.dump();
        EXPECT_GT(pose["sigma_deg"][i].get<double>(), 1e-3) << pose.dump();
        EXPECT_LT(pose["sigma_deg"][i].get<double>(), 5.0) << pose.dump();
      }
      ASSERT_EQ(pose["cov"].size(), 36u);
      EXPECT_NEAR(std::sqrt(pose["cov"][0].get<double>()), pose["sigma_m"][0].get<double>(),
                  1e-4);  // printed to 0.1 mm
      EXPECT_NEAR(pose["cov"][1].get<double>(), pose["cov"][6].get<double>(), 1e-9);
    } else {
      ++imu;
      const auto it = imu_rate.find(key);
      if (it == imu_rate.end()) continue;  // after the last scan: not in trajectory_imu.tum
      EXPECT_LE(pose["age_s"].get<double>(), 0.5);
      const Eigen::Vector3d p_level = R_level_odom * p;
      EXPECT_LT((it->second - p_level).norm(), 0.3) << pose.dump();  // garbage: metres off
      if (pose["age_s"].get<double>() > 0.15) continue;
      ++imu_fresh;  // dead-reckoned less than 1.5 scans: close to the run's IMU-rate pose
      if ((it->second - p_level).norm() < 0.05) ++imu_fresh_near;
    }
  }
  EXPECT_EQ(scans, online.size());
  EXPECT_GE(with_covariance + 1, scans);
  // At most 200 Hz over the 1.4 s after the odom frame is levelled; fewer on a loaded machine,
  // where the odometry lags by more than the 1 s that IMU-rate poses are dead-reckoned.
  EXPECT_GT(imu, 20u);
  EXPECT_GT(imu_fresh_near, imu_fresh * 9 / 10);
}

// Foxglove's own protocol client (tools/foxglove-check, @foxglove/ws-protocol from npm) connects
// to a live run and receives the poses, the IMU-rate poses, the keyframes and the scan health.
TEST(LiveCli, AFoxgloveClientReceivesPosesKeyframesAndHealth) {
  test::TempDir dir;
  const auto sim = test::simulateCapture(dir);
  const int ws_port = 7505 + portOffset();
  YAML::Node config = YAML::LoadFile(liveConfig(sim, 3.0).string());
  config["live"]["foxglove"] = fmt::format("127.0.0.1:{}", ws_port);
  config["live"]["pose_udp"] = "";
  const auto config_path = dir.write("foxglove.yaml", YAML::Dump(config) + "\n");
  auto client = std::async(std::launch::async, [&] {
    return test::runCommand(fmt::format(
        "node tools/foxglove-check/foxglove-check.mjs ws://127.0.0.1:{} 300 2>&1", ws_port));
  });
  const auto out = sim / "foxglove_run";
  auto live = startLive(config_path, out);
  ASSERT_EQ(test::runTaiga(fmt::format("replay {} --rate 1 --port-offset {}",
                                       (sim / "capture.pcap").string(), portOffset()))
                .exit_code,
            0);
  const test::TaigaResult run = live.get();
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const test::TaigaResult received = client.get();
  ASSERT_EQ(received.exit_code, 0) << received.output << " (run scripts/setup.sh)";
  const nlohmann::json j = nlohmann::json::parse(received.output);
  EXPECT_EQ(j["reason"], "closed by the server");
  const nlohmann::json& topics = j["topics"];
  ASSERT_TRUE(topics.contains("/taiga/pose")) << received.output.substr(0, 500);
  EXPECT_EQ(topics["/taiga/pose"]["schemaName"], "foxglove.PoseInFrame");
  EXPECT_EQ(topics["/taiga/keyframes"]["schemaName"], "foxglove.PointCloud");

  // The client connected before the first scan: every published pose, as in trajectory_online.
  const auto online = tumPositions(out / "trajectory_online.tum");
  const nlohmann::json& poses = topics["/taiga/pose"]["messages"];
  EXPECT_EQ(poses.size(), online.size());
  for (const nlohmann::json& m : poses) {
    const double t_s =
        m["timestamp"]["sec"].get<double>() + 1e-9 * m["timestamp"]["nsec"].get<double>();
    const auto it = online.find(std::llround(t_s * 1e4));
    ASSERT_NE(it, online.end()) << m.dump();
    const nlohmann::json& p = m["pose"]["position"];
    EXPECT_LT((it->second - Eigen::Vector3d(p["x"], p["y"], p["z"])).norm(), 1e-6);
  }
  EXPECT_GT(topics["/taiga/imu_pose"]["messages"].size(), 20u);  // see the test above
  const nlohmann::json& scans = topics["/taiga/scan"]["messages"];
  EXPECT_EQ(scans.size() + 1, online.size());  // every scan registered: all but the first
  for (const nlohmann::json& s : scans) EXPECT_GT(s["points"].get<double>(), 500.0);
  const nlohmann::json& keyframes = topics["/taiga/keyframes"]["messages"];
  EXPECT_GE(keyframes.size(), 3u);
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    EXPECT_GT(keyframes[k]["points"].get<double>(), 1000.0);
    EXPECT_EQ(keyframes[k]["keyframe"], k);
  }
  const nlohmann::json& health = topics["/taiga/health"]["messages"];
  EXPECT_EQ(health.size(), online.size());
  for (const nlohmann::json& h : health) EXPECT_EQ(h["status"], "ok");
}

// A client that connects while a run goes gets the map so far (every keyframe once, in order),
// the mapping graph's keyframe poses after each keyframe, its loop closures, and from then on the
// online georeference and the online tree map: here a recording with GNSS fixes, run from the
// file at full speed with mapping.trees, whose walk closes its loop. The client listens until the
// server closes (300 s at most): with 60 s it quit before the final tree list of a run slowed by
// a loaded machine (111 s under a CI beside a build).
TEST(LiveCli, AFoxgloveClientThatJoinsLateGetsTheMapGraphLoopsGeoreferenceAndTrees) {
  test::TempDir dir;
  const auto sim = dir.file("sim");
  ASSERT_EQ(test::runTaiga("simulate --scenario handheld-loop --duration 30 --beams 32 --columns "
                           "512 --seed 4 --out " +
                           sim.string())
                .exit_code,
            0);
  const int ws_port = 7505 + portOffset();
  YAML::Node config = YAML::LoadFile((sim / "rig.yaml").string());
  config["live"]["foxglove"] = fmt::format("127.0.0.1:{}", ws_port);
  config["mapping"]["trees"] = true;
  const auto config_path = dir.write("foxglove.yaml", YAML::Dump(config) + "\n");
  auto client = std::async(std::launch::async, [&] {
    return test::runCommand(fmt::format(
        "node tools/foxglove-check/foxglove-check.mjs ws://127.0.0.1:{} 300 2>&1", ws_port));
  });
  const auto out = sim / "run";
  const test::TaigaResult run =
      test::runTaiga(fmt::format("run {} --config {} --out {}", (sim / "recording.bag").string(),
                                 config_path.string(), out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const test::TaigaResult received = client.get();
  ASSERT_EQ(received.exit_code, 0) << received.output << " (run scripts/setup.sh)";
  const nlohmann::json topics = nlohmann::json::parse(received.output)["topics"];

  const auto keyframes_tum = tumPositions(out / "keyframes.tum");
  const nlohmann::json& keyframes = topics["/taiga/keyframes"]["messages"];
  ASSERT_EQ(keyframes.size(), keyframes_tum.size());
  for (std::size_t k = 0; k < keyframes.size(); ++k) EXPECT_EQ(keyframes[k]["keyframe"], k);

  // The local map at the keyframes after the client subscribed.
  const nlohmann::json& local_maps = topics["/taiga/local_map"]["messages"];
  ASSERT_FALSE(local_maps.empty());
  for (const nlohmann::json& m : local_maps) EXPECT_GT(m["points"].get<double>(), 1000.0);

  // The graph's last poses are the final keyframe poses (keyframes.tum), levelled at the end.
  const nlohmann::json& graphs = topics["/taiga/keyframe_poses"]["messages"];
  ASSERT_FALSE(graphs.empty());
  EXPECT_EQ(topics["/taiga/keyframe_poses"]["schemaName"], "foxglove.PosesInFrame");
  const nlohmann::json& poses = graphs.back()["poses"];
  ASSERT_EQ(poses.size(), keyframes_tum.size());
  const lie::SO3 R_level_map = finalLevelling(out);
  std::size_t k = 0;
  for (const auto& [t, p_final] : keyframes_tum) {
    const nlohmann::json& p = poses[k++]["position"];
    EXPECT_LT((p_final - R_level_map * Eigen::Vector3d(p["x"], p["y"], p["z"])).norm(), 0.01) << k;
  }

  // Every accepted loop closure of loops.csv, as keyframe pairs.
  std::vector<std::pair<int, int>> accepted;
  std::ifstream loops_csv(out / "loops.csv");
  std::string line;
  std::getline(loops_csv, line);
  while (std::getline(loops_csv, line)) {
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    if (fields.at(9) == "1") accepted.emplace_back(std::stoi(fields[1]), std::stoi(fields[2]));
  }
  ASSERT_GE(accepted.size(), 1u) << "the walk closes its loop";
  const nlohmann::json& loops = topics["/taiga/loops"]["messages"];
  ASSERT_EQ(loops.size(), accepted.size());
  for (std::size_t i = 0; i < loops.size(); ++i) {
    EXPECT_EQ(loops[i]["keyframe"], accepted[i].first);
    EXPECT_EQ(loops[i]["candidate"], accepted[i].second);
  }

  // The online tree map: the last list sent is the final trees.csv.
  const nlohmann::json& tree_lists = topics["/taiga/trees"]["messages"];
  ASSERT_FALSE(tree_lists.empty());
  std::ifstream trees_csv(out / "trees.csv");
  std::size_t stems = 0;
  for (std::getline(trees_csv, line); std::getline(trees_csv, line);) ++stems;
  EXPECT_GT(stems, 5u);
  EXPECT_EQ(tree_lists.back()["trees"].size(), stems);

  // The online georeference in the grid and as latitude and longitude (the simulator's forest
  // is in Finland), the last one as georef/trajectory_online_epsg3067.csv has it.
  const nlohmann::json& grid = topics["/taiga/georef"]["messages"];
  const nlohmann::json& fixes = topics["/taiga/fix"]["messages"];
  ASSERT_GT(grid.size(), 50u);
  ASSERT_EQ(fixes.size(), grid.size());
  for (const nlohmann::json& f : fixes) {
    EXPECT_GT(f["latitude"].get<double>(), 59.5);
    EXPECT_LT(f["latitude"].get<double>(), 70.5);
    EXPECT_GT(f["longitude"].get<double>(), 19.0);
    EXPECT_LT(f["longitude"].get<double>(), 32.0);
    EXPECT_EQ(f["position_covariance_type"], 2);
  }
  std::ifstream online_csv(out / "georef" / "trajectory_online_epsg3067.csv");
  std::string last;
  while (std::getline(online_csv, line)) last = line;
  std::stringstream row(last);
  std::string t_field, easting_field;
  std::getline(row, t_field, ',');
  std::getline(row, easting_field, ',');
  EXPECT_EQ(grid.back()["epsg"], 3067);
  EXPECT_NEAR(grid.back()["t_s"].get<double>(), std::stod(t_field), 1e-5);
  EXPECT_NEAR(grid.back()["easting_m"].get<double>(), std::stod(easting_field), 1e-3);

  // The server's account in summary.json: one client, messages sent, nothing dropped from the
  // history a late client receives (30 s of a walk is well within its budget).
  const nlohmann::json streams = nlohmann::json::parse(readText(out / "summary.json"))["streams"];
  EXPECT_EQ(streams["foxglove_clients"], 1);
  EXPECT_GT(streams["foxglove_messages"].get<int>(), 100);
  EXPECT_EQ(streams["foxglove_history_dropped"], 0);
}

// The packets of one sensor configuration, and metadata that describes another profile or
// another sensor: the run ends with exit 2 and says which.
TEST(LiveCli, MetadataOfAnotherProfileOrSensorIsNamed) {
  test::TempDir dir;
  const auto sim = test::simulateCapture(dir);
  const nlohmann::json metadata = nlohmann::json::parse(readText(sim / "capture.json"));
  nlohmann::json other_profile = metadata, other_sensor = metadata;
  other_profile["lidar_data_format"]["udp_profile_lidar"] = "LEGACY";
  other_profile["config_params"]["udp_profile_lidar"] = "LEGACY";
  other_sensor["sensor_info"]["prod_sn"] = "990000999999";
  for (const auto& [variant, expected] : {std::pair{other_profile, "none of the lidar packet size"},
                                          std::pair{other_sensor, "every one of the"}}) {
    SCOPED_TRACE(expected);
    YAML::Node config = YAML::LoadFile(liveConfig(sim, 3.0).string());
    config["live"]["metadata"] = dir.write("variant.json", variant.dump()).string();
    const auto config_path = dir.write("variant.yaml", YAML::Dump(config) + "\n");
    auto live = startLive(config_path, dir.file("variant_run"));
    ASSERT_EQ(test::runTaiga(fmt::format("replay {} --rate 4 --port-offset {}",
                                         (sim / "capture.pcap").string(), portOffset()))
                  .exit_code,
              0);
    const test::TaigaResult r = live.get();
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, HasSubstr(expected));
  }
}

TEST(LiveCli, SigtermEndsALiveRunWithItsOutputsWritten) {
  test::TempDir dir;
  const auto sim = test::simulateCapture(dir);
  const auto config = liveConfig(sim, 0.0);  // waits for packets until stopped
  const auto out = sim / "stopped_run";
  auto live = startLive(config, out);
  ASSERT_EQ(test::runTaiga(fmt::format("replay {} --rate 4 --port-offset {}",
                                       (sim / "capture.pcap").string(), portOffset()))
                .exit_code,
            0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  // Anchored at the executable: not the shells that run taiga and pkill.
  ASSERT_EQ(std::system(("pkill -TERM -f -- '^" + std::string(TAIGA_EXECUTABLE) +
                         " run --live --config " + config.string() + "'")
                            .c_str()),
            0);
  const test::TaigaResult r = live.get();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json summary = nlohmann::json::parse(readText(out / "summary.json"));
  EXPECT_THAT(summary["live"]["stop_reason"].get<std::string>(), HasSubstr("stop requested"));
  EXPECT_GT(summary["scans_processed"].get<int>(), 30);
  EXPECT_TRUE(std::filesystem::exists(out / "map.las"));
  EXPECT_GT(readText(out / "trajectory.tum").size(), 1000u);
}

TEST(LiveCli, ALiveRunWithoutMetadataWithARecordingOrABadPoseAddressSaysWhy) {
  test::TempDir dir;
  const auto rig = dir.write("rig.yaml", "rig: {}\n");
  const test::TaigaResult no_metadata =
      test::runTaiga("run --live --config " + rig.string() + " --out " + dir.file("x").string());
  EXPECT_EQ(no_metadata.exit_code, 2);
  EXPECT_THAT(no_metadata.output, HasSubstr("live.metadata"));
  const test::TaigaResult both =
      test::runTaiga("run " + rig.string() + " --live --out " + dir.file("y").string());
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.output, HasSubstr("either a RECORDING or --live"));
  const auto bad_pose = dir.write("pose.yaml", "live:\n  pose_udp: 9870\n");
  const test::TaigaResult pose = test::runTaiga("run --live --config " + bad_pose.string() +
                                                " --out " + dir.file("z").string());
  EXPECT_EQ(pose.exit_code, 2);
  EXPECT_THAT(pose.output, HasSubstr("live.pose_udp: expected host:port"));
}

}  // namespace
}  // namespace taiga::app
