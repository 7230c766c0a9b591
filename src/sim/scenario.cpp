#include "taiga/sim/scenario.hpp"

#include <fmt/format.h>

#include "taiga/core/errors.hpp"

namespace taiga::sim {

std::vector<std::string> scenarioNames() {
  return {"mixed", "sparse_pine", "dense_spruce", "open_field", "strip_road", "harvester"};
}

Scenario scenarioByName(const std::string& name) {
  Scenario s;
  s.name = name;
  ForestParams& f = s.forest;
  if (name == "mixed") {
    return s;  // the defaults
  }
  if (name == "sparse_pine") {
    f.stems_per_ha = 450;
    f.dbh_mean_m = 0.27;
    f.dbh_sigma_m = 0.07;
    f.species = {0.9, 0.03, 0.07};
    f.saplings_per_ha = 400;
    f.shrubs_per_ha = 1500;
    f.boulders_per_ha = 40;
    f.logs_per_ha = 10;
    return s;
  }
  if (name == "dense_spruce") {
    f.stems_per_ha = 1300;
    f.dbh_mean_m = 0.19;
    f.dbh_sigma_m = 0.07;
    f.species = {0.05, 0.9, 0.05};
    f.saplings_per_ha = 2500;
    f.shrubs_per_ha = 400;
    f.logs_per_ha = 40;
    f.path_clearance_m = 0.9;
    return s;
  }
  if (name == "open_field") {
    f.stems_per_ha = 3;
    f.saplings_per_ha = 20;
    f.shrubs_per_ha = 150;
    f.boulders_per_ha = 4;
    f.logs_per_ha = 1;
    f.terrain_undulation_m = 0.5;
    return s;
  }
  if (name == "strip_road") {
    f.stems_per_ha = 900;
    f.road_half_width_m = 2.5;
    s.motion.loop_aspect = 0.04;  // out along one wheel track, back along the other
    s.motion.look_around_deg = 12.0;
    return s;
  }
  if (name == "harvester") {  // a harvester thinning along the strip road, IMU at 500 Hz
    s = scenarioByName("strip_road");
    s.name = name;
    s.motion = MotionParams{};
    s.motion.model = MotionModel::kHarvester;
    s.motion.sensor_height_m = 3.8;  // on the cabin roof
    s.imu.rate_hz = 500.0;
    return s;
  }
  std::string names;
  for (const std::string& n : scenarioNames()) names += (names.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("--scenario {}: unknown scenario; expected one of {}", name, names));
}

}  // namespace taiga::sim
