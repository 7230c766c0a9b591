#include "taiga/io/config_yaml.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/system_config.hpp"

namespace taiga::io {
namespace {

using test::messageOf;
using ::testing::HasSubstr;

// A section with every field type the mechanism supports.
struct Everything final : ConfigSection {
  double voxel_m = 0.4;
  int threads = 2;
  bool deskew = true;
  std::string name = "default";
  Eigen::Vector3d gravity_mps2{0, 0, -9.81};
  lie::SE3 T_a_b;
  std::string method = "ndt";
  RigConfig rig;

  void visit(ConfigVisitor& v) override {
    v.field("voxel_m", voxel_m, "m");
    v.field("threads", threads, "count");
    v.field("deskew", deskew, "on/off");
    v.field("name", name, "label");
    v.field("gravity_mps2", gravity_mps2, "m/s^2");
    v.field("T_a_b", T_a_b, "pose");
    static constexpr std::array<std::string_view, 3> kMethods{"ndt", "d2d", "gicp"};
    v.choice("method", method, kMethods, "registration method");
    v.section("rig", rig, "rig");
  }
  void validate() const override {
    requirePositive("voxel_m", voxel_m, "m");
    requireInRange("threads", threads, 1, 64, "");
  }
};

Everything read(const std::string& text) {
  Everything config;
  readConfigYamlText(text, "test.yaml", config);
  return config;
}

std::string errorOf(const std::string& text) {
  return messageOf<InputError>([&] { read(text); });
}

TEST(ConfigYaml, ReadsEveryFieldTypeOverTheDefaults) {
  const Everything c = read(
      "voxel_m: 0.5\nthreads: 4\ndeskew: false\nname: forest\ngravity_mps2: [0, 0, -9.819]\n"
      "method: gicp\nT_a_b:\n  translation_m: [1, 2, 3]\n  rpy_deg: [0, 0, 90]\n");
  EXPECT_EQ(c.voxel_m, 0.5);
  EXPECT_EQ(c.threads, 4);
  EXPECT_FALSE(c.deskew);
  EXPECT_EQ(c.name, "forest");
  EXPECT_EQ(c.gravity_mps2, Eigen::Vector3d(0, 0, -9.819));
  EXPECT_EQ(c.method, "gicp");
  EXPECT_EQ(c.T_a_b.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE((c.T_a_b.rotation() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  // Keys that the file does not mention keep their defaults.
  EXPECT_EQ(c.rig.lidar_time_offset_s, 0.0);
}

TEST(ConfigYaml, ReadsRigExtrinsicsAsQuaternionOrRollPitchYaw) {
  SystemConfig config;
  readConfigYamlText(
      "rig:\n"
      "  T_body_lidar:\n    translation_m: [0.0, 0.0, 0.12]\n    quaternion_xyzw: [0, 0, 1, 0]\n"
      "  T_body_imu:\n    rpy_deg: [180, 0, 0]\n"
      "  lidar_time_offset_s: -0.002\n  imu_acceleration_unit: g\n",
      "rig.yaml", config);
  const lie::SE3& T = config.rig.T_body_lidar;
  EXPECT_EQ(T.translation(), Eigen::Vector3d(0, 0, 0.12));
  // 180 degrees about z: the lidar's x axis points along the body's -x.
  EXPECT_TRUE((T.rotation() * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(config.rig.T_body_imu.rotation().angle(), std::numbers::pi, 1e-12);
  EXPECT_EQ(config.rig.lidar_time_offset_s, -0.002);
  EXPECT_EQ(config.rig.imu_acceleration_unit, AccelerationUnit::kStandardGravity);
}

TEST(ConfigYaml, ReadsTheGyrosScaleAndAxisErrorsAsRows) {
  SystemConfig config;
  EXPECT_TRUE(config.rig.gyro_axes.isIdentity());
  readConfigYamlText("rig:\n  gyro_axes:\n    x: [1.01, 0.002, 0]\n    z: [0, -0.003, 0.99]\n",
                     "rig.yaml", config);
  Eigen::Matrix3d expected;
  expected << 1.01, 0.002, 0, 0, 1, 0, 0, -0.003, 0.99;  // y keeps its default row
  EXPECT_EQ(config.rig.gyro_axes.M_reading_true, expected);
  SystemConfig copy;
  readConfigYamlText(writeConfigYaml(config), "written.yaml", copy);
  EXPECT_EQ(copy.rig.gyro_axes.M_reading_true, expected);
}

TEST(ConfigYaml, WrittenConfigReadsBackIdentically) {
  Everything original = read("voxel_m: 0.123456789012345\nname: 'true'\n");
  original.T_a_b =
      lie::SE3(lie::SO3::fromRollPitchYaw(0.1, 0.2, 0.3), Eigen::Vector3d(0.1, 0.2, 0.3));
  const std::string text = writeConfigYaml(original);
  EXPECT_THAT(text, HasSubstr("# m"));  // documentation comes along as comments
  const Everything copy = read(text);
  EXPECT_EQ(copy.voxel_m, original.voxel_m);
  EXPECT_EQ(copy.name, "true");
  EXPECT_EQ(copy.T_a_b.translation(), original.T_a_b.translation());
  EXPECT_EQ(copy.T_a_b.rotation().quaternion().coeffs(),
            original.T_a_b.rotation().quaternion().coeffs());
}

TEST(ConfigYaml, ReadsAndWritesTheRigBoxes) {
  SystemConfig config;
  readConfigYamlText(
      "rig:\n  self_boxes_body:\n"
      "    - {min_m: [-1, -0.5, -2], max_m: [1, 0.5, -0.2]}\n"
      "    - min_m: [2, 2, 2]\n      max_m: [3, 3, 3]\n",
      "rig.yaml", config);
  ASSERT_EQ(config.rig.self_boxes_body.size(), 2u);
  EXPECT_EQ(config.rig.self_boxes_body[0].min_m, Eigen::Vector3d(-1, -0.5, -2));
  EXPECT_EQ(config.rig.self_boxes_body[1].max_m, Eigen::Vector3d(3, 3, 3));
  SystemConfig copy;
  readConfigYamlText(writeConfigYaml(config), "written.yaml", copy);
  ASSERT_EQ(copy.rig.self_boxes_body.size(), 2u);
  EXPECT_EQ(copy.rig.self_boxes_body[0].max_m, config.rig.self_boxes_body[0].max_m);
  EXPECT_EQ(copy.rig.self_boxes_body[1].min_m, config.rig.self_boxes_body[1].min_m);
}

TEST(ConfigYaml, EmptyFileMeansDefaults) {
  EXPECT_EQ(read("").voxel_m, 0.4);
  EXPECT_EQ(read("# nothing set\n").threads, 2);
}

struct BadConfig {
  const char* text;
  const char* message;
};

class ConfigYamlRejects : public ::testing::TestWithParam<BadConfig> {};

TEST_P(ConfigYamlRejects, NamingFileLineKeyAndExpectation) {
  EXPECT_THAT(errorOf(GetParam().text), HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, ConfigYamlRejects,
    ::testing::Values(
        // typos, at any depth, with a suggestion
        BadConfig{"voxel_m: 0.5\nvoxle_m: 0.3\n",
                  "test.yaml:2:1: voxle_m: unknown key; did you mean 'voxel_m'? valid keys here: "
                  "voxel_m, threads"},
        BadConfig{"rig:\n  lidar_time_ofset_s: 0.1\n",
                  "test.yaml:2:3: rig.lidar_time_ofset_s: unknown key; did you mean "
                  "'lidar_time_offset_s'?"},
        BadConfig{"T_a_b:\n  translation: [1, 2, 3]\n",
                  "test.yaml:2:3: T_a_b.translation: unknown key; did you mean 'translation_m'?"},
        BadConfig{"completely_different: 1\n",
                  "completely_different: unknown key; valid keys here"},
        // wrong types
        BadConfig{"voxel_m: fast\n",
                  "test.yaml:1:10: voxel_m: expected a finite number (m), got 'fast'"},
        BadConfig{"voxel_m: .nan\n", "voxel_m: expected a finite number (m), got '.nan'"},
        BadConfig{"voxel_m: [1, 2]\n", "voxel_m: expected a finite number (m), got a list of 2"},
        BadConfig{"threads: 2.5\n", "test.yaml:1:10: threads: expected an integer, got '2.5'"},
        BadConfig{"deskew: maybe\n", "deskew: expected true or false, got 'maybe'"},
        BadConfig{"name: [a, b]\n", "name: expected a text value, got a list of 2"},
        BadConfig{"gravity_mps2: [0, 0]\n",
                  "gravity_mps2: expected a list of 3 numbers [x, y, z] (m/s^2), got a list of 2"},
        BadConfig{"method: icp\n",
                  "test.yaml:1:9: method: expected one of ndt, d2d, gicp, got 'icp'"},
        BadConfig{"rig: 3\n", "test.yaml:1:6: rig: expected a mapping of keys, got '3'"},
        BadConfig{"rig:\n  imu_acceleration_unit: G\n",
                  "rig.imu_acceleration_unit: expected one of auto, mps2, g, got 'G'"},
        // extrinsics
        BadConfig{"T_a_b: [1, 2, 3]\n",
                  "T_a_b: expected a mapping with translation_m and quaternion_xyzw or rpy_deg"},
        BadConfig{"T_a_b:\n  quaternion_xyzw: [0, 0, 0, 2]\n",
                  "test.yaml:2:20: T_a_b.quaternion_xyzw: expected a unit quaternion in x, y, z, w "
                  "order, got norm 2.0000"},
        BadConfig{"T_a_b:\n  quaternion_xyzw: [0, 0, 1]\n",
                  "T_a_b.quaternion_xyzw: expected a list of 4 numbers [x, y, z, w]"},
        BadConfig{
            "T_a_b:\n  quaternion_xyzw: [0, 0, 0, 1]\n  rpy_deg: [0, 0, 0]\n",
            "T_a_b.rpy_deg: give the rotation either as quaternion_xyzw or as rpy_deg, not both"},
        BadConfig{"T_a_b:\n  translation_m: [0, 0, x]\n",
                  "T_a_b.translation_m: expected a finite number ([x, y, z] in m), got 'x'"},
        // out of range, located at the key
        BadConfig{"voxel_m: -0.4\n",
                  "test.yaml:1:1: voxel_m: expected a positive value, got -0.4 m"},
        BadConfig{"threads: 0\n", "test.yaml:1:1: threads: expected a value in [1, 64], got 0"},
        BadConfig{"rig:\n  lidar_time_offset_s: 50\n",
                  "test.yaml:2:3: rig.lidar_time_offset_s: expected a value in [-1, 1] s, got 50"},
        BadConfig{"rig:\n  T_body_lidar:\n    translation_m: [0, 0, 150]\n",
                  "test.yaml:2:3: rig.T_body_lidar.translation_m: expected a value in [0, 10] m "
                  "(length), got 150"},
        BadConfig{"rig:\n  gyro_axes:\n    y: [0, 1.5, 0]\n",
                  "test.yaml: rig.gyro_axes.y[1]: expected a value in [0.8, 1.2] (a scale or "
                  "axis error beyond 20 % is a unit or axis mistake), got 1.5"},
        BadConfig{"rig:\n  gyro_axes:\n    z: [0, 1]\n",
                  "rig.gyro_axes.z: expected"},
        // boxes
        BadConfig{"rig:\n  self_boxes_body: {min_m: [0, 0, 0]}\n",
                   "rig.self_boxes_body: expected a list of boxes"},
        BadConfig{"rig:\n  self_boxes_body:\n    - {min_m: [0, 0, 0]}\n",
                   "rig.self_boxes_body[0].max_m: missing: every box needs min_m and max_m"},
        BadConfig{"rig:\n  self_boxes_body:\n    - {min_m: [0, 0, 0], max_m: [1, -1, 1]}\n",
                   "rig.self_boxes_body[0].max_m: expected max_m >= min_m on every axis"},
        BadConfig{"rig:\n  self_boxes_body:\n    - {min_m: [0, 0, 0], max: [1, 1, 1]}\n",
                   "rig.self_boxes_body[0].max: unknown key; did you mean 'max_m'?"},
        // structure
        BadConfig{"voxel_m: 0.5\nvoxel_m: 0.6\n",
                  "test.yaml:2:1: voxel_m: appears twice (first on line 1)"},
        BadConfig{"voxel_m: [0.5\n", "test.yaml:2:1: YAML syntax error"},
        BadConfig{
            "- 1\n- 2\n",
            "test.yaml:1:1: expected a mapping of sections at the top level, got a list of 2"}));

TEST(ConfigYaml, ReadsFilesAndNamesMissingOnes) {
  test::TempDir dir;
  Everything config;
  readConfigYaml(dir.write("c.yaml", "threads: 3\n"), config);
  EXPECT_EQ(config.threads, 3);
  EXPECT_THAT(messageOf<InputError>([&] { readConfigYaml(dir.file("none.yaml"), config); }),
              HasSubstr("none.yaml: no such file"));
  EXPECT_THAT(messageOf<InputError>([&] { readConfigYaml(dir.path(), config); }),
              HasSubstr("is not a regular file"));
  EXPECT_THAT(
      messageOf<InputError>([&] { readConfigYaml(dir.write("bad.yaml", "threads: x\n"), config); }),
      HasSubstr("bad.yaml:1:10: threads: expected an integer"));
}

}  // namespace
}  // namespace taiga::io
