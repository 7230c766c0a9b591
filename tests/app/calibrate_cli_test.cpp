// Issue 20: `taiga calibrate` as users run it, on a simulated handheld walk whose rig.yaml is off
// by 2 deg and 10 ms (`typical` realism): the offset is found to within a millisecond, the
// rotation about every axis, and the corrected rig.yaml is a valid configuration; a 90 or 180 deg
// mounting error is found too. Bad input gets a clear error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "../support/run_taiga.hpp"
#include "../support/temp_dir.hpp"

namespace taiga::app {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

/// `taiga simulate SIMULATE_ARGS` into DIR/sim, then `taiga calibrate` of its recording with its
/// rig.yaml into DIR/calibrated (plus CALIBRATE_ARGS); `result` is the calibration's.
void simulateAndCalibrate(const test::TempDir& dir, const std::string& simulate_args,
                          const std::string& calibrate_args, test::TaigaResult* result) {
  const auto sim = dir.file("sim");
  const test::TaigaResult simulated =
      test::runTaiga("simulate " + simulate_args + " --out " + sim.string());
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  *result = test::runTaiga("calibrate " + (sim / "recording.bag").string() + " --config " +
                           (sim / "rig.yaml").string() + " --out " +
                           dir.file("calibrated").string() + calibrate_args);
}

TEST(CalibrateCli, FindsTheTimeOffsetAndRotationOfATypicalRig) {
  test::TempDir dir;
  test::TaigaResult r;
  ASSERT_NO_FATAL_FAILURE(simulateAndCalibrate(
      dir, "--scenario handheld-loop --realism typical --duration 20 --beams 32 --seed 5", "", &r));
  const auto sim = dir.file("sim");
  const auto out = dir.file("calibrated");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("offset     rig.lidar_time_offset_s"));
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "calibration.json"));
  // The truth: 10 ms at the start, drifting 10 ppm (0.1 ms over the stretch).
  EXPECT_TRUE(j["time_offset"]["observable"].get<bool>());
  EXPECT_NEAR(j["time_offset"]["estimated_s"].get<double>(), 0.010, 0.001);
  EXPECT_LT(j["time_offset"]["sigma_s"].get<double>(), 0.001);
  for (const bool observable : j["rotation"]["observable_about_body_xyz"]) EXPECT_TRUE(observable);
  // The configured rotation is 2 deg off; the estimate moves it by about that (the rest of the
  // difference to rig_truth.yaml is the gyro's own axis misalignment, docs/calibration.md).
  EXPECT_NEAR(j["rotation"]["change_deg"].get<double>(), 2.0, 0.6);
  // The lever arm (3 cm off in rig.yaml): what was applied brought the corrected rig.yaml's
  // translation nearer the truth along that axis, to within 1.5 cm (issue 20's bound).
  const auto translation = [](const std::filesystem::path& rig) {
    return YAML::LoadFile(rig.string())["rig"]["T_body_lidar"]["translation_m"]
        .as<std::vector<double>>();
  };
  const std::vector<double> configured = translation(sim / "rig.yaml");
  const std::vector<double> truth = translation(sim / "rig_truth.yaml");
  const std::vector<double> corrected = translation(out / "rig.yaml");
  const nlohmann::json& lever = j["translation"];
  for (std::size_t k = 0; k < 3; ++k) {
    if (!lever["applied_along_body_xyz"][k].get<bool>()) {
      EXPECT_NEAR(corrected[k], configured[k], 1e-9) << k;
      continue;
    }
    EXPECT_LT(std::abs(corrected[k] - truth[k]), std::abs(configured[k] - truth[k])) << k;
    EXPECT_LT(std::abs(corrected[k] - truth[k]), 0.015) << k;
  }
  EXPECT_GE(j["passes"].size(), 2u);
  EXPECT_FALSE(j["cost_curve"]["offset_s"].empty());
  // The gyro's true noise is twice rig.yaml's 2.5e-4 rad/s/sqrt(Hz); stamp jitter and the
  // registrations' own errors add to what the odometry sees (docs/calibration.md, "IMU noise").
  const nlohmann::json& noise = j["gyro_noise"];
  EXPECT_EQ(noise["verdict"], "understated") << noise.dump();
  const double measured = noise["measured_radps_sqrthz"].get<double>();
  EXPECT_GT(measured, 1.6 * 2.5e-4);
  EXPECT_LT(measured, 4.5 * 2.5e-4);
  EXPECT_LT(noise["sigma_radps_sqrthz"].get<double>(), measured / 3.0);
  // The corrected configuration is valid and says the offset and the measured density.
  const test::TaigaResult config = test::runTaiga("config " + (out / "rig.yaml").string());
  EXPECT_EQ(config.exit_code, 0) << config.output;
  EXPECT_THAT(config.output, HasSubstr("lidar_time_offset_s: 0.0"));
  std::ostringstream suggested;
  suggested << "gyro_noise_density: " << noise["suggested_radps_sqrthz"].get<double>();
  EXPECT_THAT(config.output, HasSubstr(suggested.str()));

  // A lidar mounted 90 deg about z, or upside down (180 deg about x), from what the rig says (the
  // truth is the identity): the IMU's prediction cannot start the registrations, and a
  // lidar-only pass finds the mounting first.
  std::ifstream in(sim / "rig.yaml");
  const std::string rig((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = rig.find("quaternion_xyzw: [");
  ASSERT_NE(at, std::string::npos);
  for (const std::string mounting : {"0, 0, 0.7071067811865476, 0.7071067811865476", "1, 0, 0, 0"}) {
    std::string text = rig;
    text.replace(at, text.find(']', at) + 1 - at, "quaternion_xyzw: [" + mounting + "]");
    std::ofstream(dir.file("rig_wrong.yaml")) << text;
    const auto out_wrong = dir.file("calibrated_wrong");
    const test::TaigaResult wrong =
        test::runTaiga("calibrate " + (sim / "recording.bag").string() + " --config " +
                       dir.file("rig_wrong.yaml").string() + " --out " + out_wrong.string());
    ASSERT_EQ(wrong.exit_code, 0) << mounting << wrong.output;
    const nlohmann::json j_wrong =
        nlohmann::json::parse(std::ifstream(out_wrong / "calibration.json"));
    EXPECT_EQ(j_wrong["passes"][1]["odometry"], "lidar-only") << mounting;
    const std::vector<double> q = j_wrong["rotation"]["estimated_quaternion_xyzw"];
    const double angle_deg = 2.0 * std::acos(std::min(1.0, std::abs(q[3]))) * 180.0 / M_PI;
    EXPECT_LT(angle_deg, 1.5) << mounting;  // the gyro's misalignment floor is about 0.5
    EXPECT_NEAR(j_wrong["time_offset"]["estimated_s"].get<double>(), 0.010, 0.001) << mounting;
  }
}

// A harvester that stands, then drives straight: its rotation rates are the size of the
// registrations' noise, so neither the offset nor the rotation is observable and both stay as
// configured. Until session 48 the residual (0.3 deg/s against a 0.3 deg/s signal) passed for a
// gross mounting error, and the lidar-only pass applied an 8.5 deg rotation about axes it could
// not see (14 deg on the 60 s recording of the same seed).
TEST(CalibrateCli, ARigThatBarelyTurnsKeepsItsConfiguredRotation) {
  test::TempDir dir;
  test::TaigaResult r;
  ASSERT_NO_FATAL_FAILURE(simulateAndCalibrate(
      dir, "--scenario harvester --realism typical --duration 20 --beams 32 --seed 31",
      " --no-plots", &r));
  const auto out = dir.file("calibrated");
  EXPECT_EQ(r.exit_code, 1) << r.output;  // nothing calibrated (docs/calibration.md)
  EXPECT_THAT(r.output, HasSubstr("the motion was too poor to calibrate"));
  EXPECT_THAT(r.output, Not(HasSubstr("disagree beyond noise")));
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "calibration.json"));
  EXPECT_EQ(j["rotation"]["change_deg"].get<double>(), 0.0);
  for (const bool observable : j["rotation"]["observable_about_body_xyz"]) EXPECT_FALSE(observable);
  EXPECT_FALSE(j["time_offset"]["observable"].get<bool>());
  for (const nlohmann::json& pass : j["passes"]) EXPECT_EQ(pass["odometry"], "lidar-inertial");
}

TEST(CalibrateCli, ARecordingWithoutAnImuIsBadInput) {
  test::TempDir dir;
  const auto sim = dir.file("sim");
  const auto overrides = dir.file("no_imu.yaml");
  std::ofstream(overrides) << "output:\n  imu: false\n";
  const test::TaigaResult s = test::runTaiga(
      "simulate --scenario mixed --duration 3 --beams 16 "
      "--columns 512 --overrides " +
      overrides.string() + " --out " + sim.string());
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const test::TaigaResult r = test::runTaiga("calibrate " + (sim / "recording.bag").string() +
                                             " --out " + dir.file("out").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("recording.bag"));
  EXPECT_THAT(r.output, HasSubstr("IMU"));
}

TEST(CalibrateCli, TooShortAStretchIsRefused) {
  const test::TaigaResult r = test::runTaiga("calibrate x.bag --out y --duration 2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("--duration"));
}

}  // namespace
}  // namespace taiga::app
