// recording.deskewed: auto (pipeline/sweep_check.hpp): the seam between a sweep's first and last
// firings tells a raw sweep from a cloud deskewed upstream.
#include "taiga/pipeline/sweep_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "../support/temp_dir.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/sim/realism.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"

namespace taiga::pipeline {
namespace {

/// A sweep of flat ground 1.5 m below a sensor: 16 beams, 1024 columns, the sweep fraction
/// from the column; the points of the sweep's last `lifted` share raised by `lift_m`.
struct Sweep {
  std::vector<Eigen::Vector3d> positions;
  std::vector<double> fractions;
};
Sweep groundSweep(double lift_m, double lifted) {
  constexpr int kColumns = 1024, kBeams = 16;
  Sweep s;
  for (int col = 0; col < kColumns; ++col) {
    const double azimuth = 2.0 * std::numbers::pi * col / kColumns;
    for (int beam = 0; beam < kBeams; ++beam) {
      const double elevation = -(10.0 + 2.0 * beam) * std::numbers::pi / 180.0;
      const double range_xy = 1.5 / std::tan(-elevation);
      const double u = (col + 0.5) / kColumns;
      const double z = u > 1.0 - lifted ? -1.5 + lift_m : -1.5;
      s.positions.emplace_back(range_xy * std::cos(azimuth), range_xy * std::sin(azimuth), z);
      s.fractions.push_back(u);
    }
  }
  return s;
}

TEST(SeamMismatch, IsTheOffsetOfTheLastFiringsFromTheFirstOnes) {
  const Sweep agreeing = groundSweep(0.0, 0);
  const std::optional<double> none = seamMismatch_m(agreeing.positions, agreeing.fractions);
  ASSERT_TRUE(none);
  EXPECT_LT(*none, 1e-6);
  const Sweep torn = groundSweep(0.05, 0.1);  // beyond the last wedge compared (1/12)
  const std::optional<double> five_cm = seamMismatch_m(torn.positions, torn.fractions);
  ASSERT_TRUE(five_cm);
  EXPECT_NEAR(*five_cm, 0.05, 0.005);
  // A lift elsewhere in the sweep is not the seam's business.
  Sweep middle = groundSweep(0.0, 0);
  for (std::size_t i = 0; i < middle.positions.size(); ++i)
    if (std::abs(middle.fractions[i] - 0.5) < 0.05) middle.positions[i].z() += 0.05;
  EXPECT_LT(*seamMismatch_m(middle.positions, middle.fractions), 1e-6);
}

TEST(SeamMismatch, IsEmptyWithoutSurfacesAtTheSeam) {
  const Sweep s = groundSweep(0.0, 0);
  std::vector<double> middle_only(s.fractions.size(), 0.5);
  EXPECT_FALSE(seamMismatch_m(s.positions, middle_only));
  EXPECT_FALSE(seamMismatch_m({}, {}));
}

/// The check on a short handheld walk written in `layout`, told the rig its user would write.
SweepCheck checkSimulated(const std::string& layout, std::uint64_t seed,
                          const std::string& realism = "typical") {
  test::TempDir dir;
  sim::Scenario scenario = sim::scenarioByName("handheld-loop");
  sim::applyRealism(realism, scenario);
  sim::applyScenarioOverridesText("output: {point_layout: " + layout + ", gnss: false}\n",
                                  "test overrides", scenario);
  scenario.lidar.beams = 32;
  sim::writeSimulation(sim::Simulation(scenario, 8.0, seed), dir.path());
  SystemConfig config;
  io::readConfigYaml(dir.path() / "rig.yaml", config);
  EXPECT_EQ(config.recording.deskewed, RecordingConfig::Deskewed::kAuto);  // as written
  return checkSweeps(dir.path() / "recording.bag", config);
}

// Measured (32 beams, 8 s, typical realism, the stated rig; the verdict's bounds 0.84x and 1.2x):
// deskewed upstream 0.21x / 0.22x, raw sweeps 4.33x / 2.90x on seeds 1 / 2 (31-36 scans used).
TEST(SweepCheck, TellsCloudsDeskewedUpstreamFromRawSweepsWithoutTimes) {
  for (const std::uint64_t seed : {1u, 2u}) {
    SCOPED_TRACE(seed);
    const SweepCheck deskewed = checkSimulated("deskewed", seed);
    EXPECT_EQ(deskewed.verdict, SweepCheck::Verdict::kDeskewedUpstream) << deskewed.text;
    EXPECT_GE(deskewed.scans_used, 20u);
    const SweepCheck raw = checkSimulated("untimed", seed);
    EXPECT_EQ(raw.verdict, SweepCheck::Verdict::kRawSweep) << raw.text;
    EXPECT_GE(raw.scans_used, 20u);
  }
}

TEST(SweepCheck, IsNotNeededWhenThePointsCarryTimes) {
  const SweepCheck timed = checkSimulated("ouster", 1, "ideal");
  EXPECT_EQ(timed.verdict, SweepCheck::Verdict::kNotNeeded);
  EXPECT_EQ(timed.scans_used, 0u);
}

TEST(SweepCheck, ResolvesOnlyWhatTheConfigurationLeftToIt) {
  test::TempDir dir;
  sim::Scenario scenario = sim::scenarioByName("handheld-loop");
  sim::applyScenarioOverridesText("output: {point_layout: deskewed, gnss: false}\n", "overrides",
                                  scenario);
  scenario.lidar.beams = 32;
  sim::writeSimulation(sim::Simulation(scenario, 8.0, 3), dir.path());
  SystemConfig config;
  io::readConfigYaml(dir.path() / "rig.yaml", config);
  const std::optional<SweepCheck> found = resolveDeskewed(dir.path() / "recording.bag", config);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->verdict, SweepCheck::Verdict::kDeskewedUpstream) << found->text;
  EXPECT_TRUE(config.recording.pointsAtStamp());
  config.recording.deskewed = RecordingConfig::Deskewed::kNo;  // the user's word stands
  EXPECT_FALSE(resolveDeskewed(dir.path() / "recording.bag", config));
  EXPECT_FALSE(config.recording.pointsAtStamp());
}

}  // namespace
}  // namespace taiga::pipeline
