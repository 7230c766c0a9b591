#include "taiga/sim/scenario.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <utility>

#include "taiga/core/errors.hpp"

namespace taiga::sim {
namespace {

// Forest stands.
void sparsePine(Scenario& s) {
  ForestParams& f = s.forest;
  f.stems_per_ha = 450;
  f.dbh_mean_m = 0.27;
  f.dbh_sigma_m = 0.07;
  f.species = {0.9, 0.03, 0.07};
  f.saplings_per_ha = 400;
  f.shrubs_per_ha = 1500;
  f.boulders_per_ha = 40;
  f.logs_per_ha = 10;
}

void denseSpruce(Scenario& s) {
  ForestParams& f = s.forest;
  f.stems_per_ha = 1300;
  f.dbh_mean_m = 0.19;
  f.dbh_sigma_m = 0.07;
  f.species = {0.05, 0.9, 0.05};
  f.saplings_per_ha = 2500;
  f.shrubs_per_ha = 400;
  f.logs_per_ha = 40;
  f.path_clearance_m = 0.9;
}

// Almost nothing to register against: the degenerate case.
void openField(Scenario& s) {
  ForestParams& f = s.forest;
  f.stems_per_ha = 3;
  f.saplings_per_ha = 20;
  f.shrubs_per_ha = 150;
  f.boulders_per_ha = 4;
  f.logs_per_ha = 1;
  f.terrain_undulation_m = 0.5;
}

void stripRoad(Scenario& s) {
  s.forest.stems_per_ha = 900;
  s.forest.road_half_width_m = 2.5;
  s.motion.loop_aspect = 0.06;  // out along one wheel track, back along the other
  s.motion.loop_straightness = 4.0;  // and a U-turn of about 1 m radius at each end
  s.motion.look_around_deg = 12.0;
}

// Handheld plot surveys in the mixed stand, with an IMU that reports its filter's orientation
// (docs/simulator.md, "IMU").
void handheldLoop(Scenario& s) {
  s.duration_s = 180.0;  // one loop of about 230 m
  s.imu.orientation_output = true;
}

void handheldLong(Scenario& s) {
  s.duration_s = 900.0;
  s.motion.loop_lobes = 4;             // a cloverleaf through the start area: several loops
  s.motion.max_loop_length_m = 500.0;  // four lobes reaching 45-80 m out, walked about twice
  s.imu.orientation_output = true;
}

// A forest harvester thinning along the strip road, IMU at 500 Hz (motion: harvester_motion.cpp).
void harvester(Scenario& s) {
  stripRoad(s);
  s.motion = MotionParams{};
  s.motion.model = MotionModel::kHarvester;
  s.motion.sensor_height_m = 3.8;  // on the cabin roof
  s.imu.rate_hz = 500.0;
  s.imu.orientation_output = true;
  s.duration_s = 300.0;  // about five tree stops
}

struct Entry {
  const char* name;
  std::function<void(Scenario&)> configure;  // changes to the defaults (= mixed)
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> entries = {
      {"mixed", [](Scenario&) {}},
      {"sparse_pine", sparsePine},
      {"dense_spruce", denseSpruce},
      {"strip_road", stripRoad},
      {"open-field", openField},
      {"handheld-loop", handheldLoop},
      {"handheld-long", handheldLong},
      {"harvester", harvester},
  };
  return entries;
}

/// Hyphens and underscores are the same in scenario names.
std::string normalized(std::string name) {
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

}  // namespace

std::vector<std::string> scenarioNames() {
  std::vector<std::string> names;
  for (const Entry& e : registry()) names.emplace_back(e.name);
  return names;
}

Scenario scenarioByName(const std::string& name) {
  for (const Entry& e : registry()) {
    if (normalized(e.name) != normalized(name)) continue;
    Scenario s;
    s.name = e.name;
    e.configure(s);
    return s;
  }
  std::string names;
  for (const std::string& n : scenarioNames()) names += (names.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("--scenario {}: unknown scenario; expected one of {}", name, names));
}

}  // namespace taiga::sim
