#include "taiga/core/config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/system_config.hpp"

namespace taiga {
namespace {

using test::messageOf;
using ::testing::HasSubstr;

struct Inner final : ConfigSection {
  double voxel_m = 0.4;
  void visit(ConfigVisitor& v) override { v.field("voxel_m", voxel_m, "m"); }
  void validate() const override { requirePositive("voxel_m", voxel_m, "m"); }
};

struct Outer final : ConfigSection {
  Inner inner;
  void visit(ConfigVisitor& v) override { v.section("inner", inner, "an inner section"); }
};

TEST(Config, ValidateAllNamesTheFullPathOfTheBadKey) {
  Outer outer;
  validateAll(outer);
  outer.inner.voxel_m = -1.0;
  const std::string message = messageOf<ConfigError>([&] { validateAll(outer); });
  EXPECT_EQ(message, "inner.voxel_m: expected a positive value, got -1 m");
}

TEST(Config, RangeChecksRejectNaN) {
  EXPECT_THAT(messageOf<ConfigError>([] { requireInRange("k", std::nan(""), 0.0, 1.0, "s"); }),
              HasSubstr("k: expected a value in [0, 1] s, got nan"));
  EXPECT_THROW(requireNonNegative("k", std::nan(""), ""), ConfigError);
  EXPECT_NO_THROW(requireNonNegative("k", 0.0, ""));
}

TEST(RigConfig, RejectsUnitMistakes) {
  SystemConfig config;
  validateAll(config);
  config.rig.lidar_time_offset_s = 25.0;  // milliseconds given as seconds
  EXPECT_THAT(messageOf<ConfigError>([&] { validateAll(config); }),
              HasSubstr("rig.lidar_time_offset_s: expected a value in [-1, 1] s, got 25"));
  config.rig.lidar_time_offset_s = 0.0;
  config.rig.T_body_lidar = lie::SE3(lie::SO3(), Eigen::Vector3d(0, 0, 120.0));  // mm given as m
  EXPECT_THAT(messageOf<ConfigError>([&] { validateAll(config); }),
              HasSubstr("rig.T_body_lidar.translation_m"));
}

// A visitor that records the choice offered for an enum field and answers with another name.
struct ChoiceAnswer final : ConfigVisitor {
  std::string offered, answer = "g";
  std::vector<std::string> allowed;
  void field(std::string_view, double&, std::string_view) override {}
  void field(std::string_view, int&, std::string_view) override {}
  void field(std::string_view, bool&, std::string_view) override {}
  void field(std::string_view, std::string&, std::string_view) override {}
  void field(std::string_view, Eigen::Vector3d&, std::string_view) override {}
  void field(std::string_view, lie::SE3&, std::string_view) override {}
  void field(std::string_view, std::vector<Box>&, std::string_view) override {}
  void choice(std::string_view, std::string& value, std::span<const std::string_view> names,
              std::string_view) override {
    offered = value;
    allowed.assign(names.begin(), names.end());
    value = answer;
  }
  void section(std::string_view, ConfigSection&, std::string_view) override {}
};

TEST(Config, EnumFieldsAreChoicesByName) {
  RigConfig rig;
  ChoiceAnswer visitor;
  rig.visit(visitor);
  EXPECT_EQ(visitor.offered, "auto");
  EXPECT_EQ(visitor.allowed, (std::vector<std::string>{"auto", "mps2", "g"}));
  EXPECT_EQ(rig.imu_acceleration_unit, AccelerationUnit::kStandardGravity);
}

}  // namespace
}  // namespace taiga
