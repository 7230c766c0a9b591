// The `taiga` command as users and scripts see it: exit codes, help, version and error messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/rosbag.hpp"

namespace {

using ::testing::HasSubstr;

using Result = taiga::test::TaigaResult;
using taiga::test::runTaiga;

TEST(Cli, PrintsItsVersion) {
  const Result r = runTaiga("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("taiga 0."));
}

TEST(Cli, EverySubcommandHasHelp) {
  for (const char* name :
       {"simulate", "info", "export", "register", "run", "eval", "compare", "georef", "config",
        "export-map", "calibrate"}) {
    const Result r = runTaiga(std::string(name) + " --help");
    EXPECT_EQ(r.exit_code, 0) << name;
    EXPECT_THAT(r.output, HasSubstr(std::string("Usage: ") + TAIGA_EXECUTABLE + " " + name))
        << name;
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(runTaiga("").exit_code, 2);
  EXPECT_EQ(runTaiga("fly").exit_code, 2);
  const Result missing = runTaiga("eval --est a.tum");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("--ref is required"));
  const Result bad_choice = runTaiga("register a.ply b.ply --method icp");
  EXPECT_EQ(bad_choice.exit_code, 2);
  EXPECT_THAT(bad_choice.output, HasSubstr("icp not in {ndt,d2d,gicp}"));
}

// One second of a small recording: 10 scans of 64 points, 200 IMU samples in g, one fix.
void writeSmallBag(const std::filesystem::path& path) {
  using namespace taiga;
  io::BagWriter writer(path);
  for (int i = 0; i < 200; ++i) {
    ImuSample imu;
    imu.t_s = 1700000000.0 + 0.005 * i;
    imu.acceleration_imu_mps2 = {0.0, 0.0, 1.0};  // in g, as some drivers publish
    writer.writeImu("/imu", "imu", imu);
  }
  for (int s = 0; s < 10; ++s) {
    io::Scan scan;
    scan.index = s;
    for (int c = 0; c < 64; ++c) {
      scan.cloud_in_lidar.positions.emplace_back(5.0, 0.1 * c, 1.0);
      scan.cloud_in_lidar.times_s.push_back(1700000000.0 + 0.1 * s + 0.099 * c / 63);
      scan.cloud_in_lidar.intensities.push_back(float(c));
      scan.cloud_in_lidar.rings.push_back(static_cast<std::uint16_t>(c % 16));
    }
    std::tie(scan.t_start_s, scan.t_end_s) = scan.cloud_in_lidar.timeSpan();
    writer.writeScan("/os_cloud_node/points", "os_sensor", scan);
  }
}

TEST(Cli, InfoSummarizesABagAsTextAndJson) {
  taiga::test::TempDir dir;
  writeSmallBag(dir.file("small.bag"));
  const Result text = runTaiga("info " + dir.file("small.bag").string());
  EXPECT_EQ(text.exit_code, 0) << text.output;
  EXPECT_THAT(text.output, HasSubstr("(ROS1 bag)"));
  EXPECT_THAT(text.output, HasSubstr("/os_cloud_node/points"));
  EXPECT_THAT(text.output, HasSubstr("per-point times: field 't' (uint32, ns after the stamp)"));
  EXPECT_THAT(text.output, HasSubstr("acceleration is in g"));

  const Result json = runTaiga("info --json " + dir.file("small.bag").string(), false);
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto j = nlohmann::json::parse(json.output);
  EXPECT_EQ(j["streams"][0]["count"], 10);
  EXPECT_NEAR(j["streams"][0]["rate_hz"].get<double>(), 10.0, 1e-3);  // stamps are whole ns
  EXPECT_NEAR(j["streams"][1]["rate_hz"].get<double>(), 200.0, 1e-3);
  EXPECT_EQ(j["scans"]["median_points"], 64);
  EXPECT_EQ(j["scans"]["scans_with_monotonic_times"], 10);
  EXPECT_NEAR(j["imu"]["median_acceleration_mps2"].get<double>(), 9.80665, 1e-9);
  EXPECT_TRUE(j["error"].is_null());
}

TEST(Cli, InfoReadsAnOusterCaptureWithTheMetadataBesideIt) {
  // The OS1-128 capture's metadata is named without the capture's "_lb_n3" suffix.
  const Result r = runTaiga("info ../shared/data/ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap --json", false);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["format"], "Ouster capture");
  std::map<std::string, int> counts;
  for (const auto& stream : j["streams"]) counts[stream["kind"].get<std::string>()] = stream["count"].get<int>();
  EXPECT_EQ(counts["lidar"], 3);
  EXPECT_EQ(counts["imu"], 30);
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();
}

TEST(Cli, InfoOnACaptureWithoutMetadataSaysWhatToGive) {
  taiga::test::TempDir dir;
  std::filesystem::copy_file("../shared/data/ouster/crc_test.pcap", dir.path() / "drive.pcap");
  const Result r = runTaiga(fmt::format("info {}", (dir.path() / "drive.pcap").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("drive.pcap: an Ouster capture needs the sensor metadata JSON"));
  EXPECT_THAT(r.output, HasSubstr("recording.ouster_metadata"));
}

TEST(Cli, InfoWarnsAboutTimesThatDoNotSpanTheScan) {
  taiga::test::TempDir dir;
  std::filesystem::create_directories(dir.file("rec/scans"));
  // Per-point times in microseconds given where nanoseconds are expected: 1000x too short.
  for (int s = 0; s < 5; ++s) {
    std::string pcd = "FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH 10\nPOINTS 10\nDATA ascii\n";
    for (int i = 0; i < 10; ++i) pcd += fmt::format("{} 1 1 {}\n", i + 1, i * 10000);
    dir.write(fmt::format("rec/scans/{}.pcd", 100.0 + 0.1 * s), pcd);
  }
  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy,wz\n100,0,0,9.8,0,0,0\n100.5,0,0,9.8,0,0,0\n");
  const Result r = runTaiga("info " + dir.file("rec").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("(folder recording)"));
  EXPECT_THAT(r.output, HasSubstr("per-point times span 0.0001 s per scan (median) but scans come every 0.1000 s"));
}

TEST(Cli, ExportWritesOneScanOrAll) {
  taiga::test::TempDir dir;
  writeSmallBag(dir.file("small.bag"));
  const Result one = runTaiga("export " + dir.file("small.bag").string() + " --scan 3 --out " + dir.file("s3.ply").string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const taiga::io::DecodedPoints points = taiga::io::readPointCloudFile(dir.file("s3.ply"), 0.0);
  EXPECT_EQ(points.cloud.size(), 64u);
  EXPECT_NEAR(points.cloud.times_s.front(), 1700000000.3, 1e-6);

  const Result all = runTaiga("export " + dir.file("small.bag").string() + " --all --format las --out " + dir.file("all").string());
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_TRUE(std::filesystem::exists(dir.file("all/scan_000009.las")));

  const Result missing = runTaiga("export " + dir.file("small.bag").string() + " --scan 10 --out " + dir.file("x.ply").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("has no scan 10 (scans are numbered from 0)"));
  const Result no_topic = runTaiga("info " + dir.file("s3.ply").string());
  EXPECT_EQ(no_topic.exit_code, 2);
  EXPECT_THAT(no_topic.output, HasSubstr("not a recording taiga reads"));
}

// georef was the last subcommand that exited 69 (not implemented); its own tests are in
// tests/georef/georef_cli_test.cpp.
TEST(Cli, GeorefWithAMissingTrajectoryNamesIt) {
  const Result r = runTaiga("georef --traj /nonexistent/t.tum --gnss g.csv --method pf6 --out /tmp/unused");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/t.tum"));
}

TEST(Cli, ConfigPrintsDefaultsAndNamesBadKeys) {
  const Result defaults = runTaiga("config");
  EXPECT_EQ(defaults.exit_code, 0);
  EXPECT_THAT(defaults.output, HasSubstr("T_body_lidar:"));

  taiga::test::TempDir dir;
  const auto typo = dir.write(
      "typo.yaml", "rig:\n  T_body_lidar:\n    rpy_deg: [0, 0, 180]\n  lidar_offset_s: 0.1\n");
  const Result r = runTaiga("config " + typo.string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("taiga: error: " + typo.string() +
                                  ":4:3: rig.lidar_offset_s: unknown key"));

  // A key that moved says where to (issue 23: one GNSS setting for fusion and georef).
  const auto moved = dir.write("moved.yaml", "mapping:\n  gnss_correlation_time_s: 60\n");
  const Result moved_result = runTaiga("config " + moved.string());
  EXPECT_EQ(moved_result.exit_code, 2);
  EXPECT_THAT(moved_result.output,
              HasSubstr(":2:3: mapping.gnss_correlation_time_s: moved to "
                        "georef.error_correlation_time_s"));

  const auto good = dir.write("good.yaml", "rig:\n  T_body_lidar:\n    rpy_deg: [0, 0, 180]\n");
  const Result ok = runTaiga("config " + good.string());
  EXPECT_EQ(ok.exit_code, 0);
  EXPECT_THAT(ok.output, HasSubstr("quaternion_xyzw: [0, 0, 1, 6.123233995736766e-17]"));

  const auto threads = dir.write("threads.yaml", "compute:\n  threads: -2\n");
  const Result bad_threads = runTaiga("config " + threads.string());
  EXPECT_EQ(bad_threads.exit_code, 2);
  EXPECT_THAT(bad_threads.output, HasSubstr("compute.threads: expected a value in [0, 1024]"));
  EXPECT_EQ(runTaiga("run x.bag --out y --threads -1").exit_code, 2);  // the flag is checked too
}

}  // namespace
