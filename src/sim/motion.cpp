#include "taiga/sim/motion.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "motion_models.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::sim {
namespace {
void require(bool ok, const char* field, const std::string& expected, double found) {
  if (!ok) throw InputError(fmt::format("motion.{}: expected {}, found {}", field, expected, found));
}
}  // namespace

void MotionParams::validate() const {
  require(speed_mps > 0.0, "speed_mps", "> 0", speed_mps);
  require(sensor_height_m > 0.0, "sensor_height_m", "> 0", sensor_height_m);
  require(loop_lobes == 1 || loop_lobes == 3 || loop_lobes == 4, "loop_lobes", "1, 3 or 4",
          loop_lobes);
  require(loop_straightness >= 0.0 && loop_straightness <= 6.0, "loop_straightness", "0 .. 6",
          loop_straightness);
  require(lobe_size_variation >= 0.0 && lobe_size_variation <= 0.6, "lobe_size_variation",
          "0 .. 0.6", lobe_size_variation);
  require(speed_variation >= 0.0 && speed_variation < 0.9, "speed_variation", "0 .. 0.9",
          speed_variation);
  require(pause_interval_s >= 0.0, "pause_interval_s", ">= 0 (0: no pauses)", pause_interval_s);
  require(pause_min_s >= 0.0, "pause_min_s", ">= 0", pause_min_s);
  require(pause_max_s >= pause_min_s, "pause_max_s", ">= pause_min_s", pause_max_s);
  require(pause_ramp_s > 0.0, "pause_ramp_s", "> 0", pause_ramp_s);
  require(fast_turn_interval_s >= 0.0, "fast_turn_interval_s", ">= 0 (0: no fast turns)",
          fast_turn_interval_s);
  require(fast_turn_min_deg > 0.0 && fast_turn_min_deg <= 180.0, "fast_turn_min_deg", "0 .. 180",
          fast_turn_min_deg);
  require(fast_turn_max_deg >= fast_turn_min_deg && fast_turn_max_deg <= 180.0,
          "fast_turn_max_deg", "fast_turn_min_deg .. 180", fast_turn_max_deg);
  require(fast_turn_rate_deg_s > 0.0, "fast_turn_rate_deg_s", "> 0", fast_turn_rate_deg_s);
  require(harvester_speed_min_mps > 0.0, "harvester_speed_min_mps", "> 0",
          harvester_speed_min_mps);
  require(harvester_speed_max_mps >= harvester_speed_min_mps, "harvester_speed_max_mps",
          ">= harvester_speed_min_mps", harvester_speed_max_mps);
  require(harvester_ramp_s > 0.0, "harvester_ramp_s", "> 0", harvester_ramp_s);
  require(harvester_drive_min_m >= harvester_speed_max_mps * harvester_ramp_s,
          "harvester_drive_min_m", "at least harvester_speed_max_mps x harvester_ramp_s",
          harvester_drive_min_m);
  require(harvester_drive_max_m >= harvester_drive_min_m, "harvester_drive_max_m",
          ">= harvester_drive_min_m", harvester_drive_max_m);
  require(harvester_stop_min_s >= 10.0, "harvester_stop_min_s",
          ">= 10 (the boom swings out and back)", harvester_stop_min_s);
  require(harvester_stop_max_s >= harvester_stop_min_s, "harvester_stop_max_s",
          ">= harvester_stop_min_s", harvester_stop_max_s);
  require(harvester_reverse_probability >= 0.0 && harvester_reverse_probability <= 1.0,
          "harvester_reverse_probability", "0 .. 1", harvester_reverse_probability);
  require(harvester_reverse_max_m >= 1.5, "harvester_reverse_max_m", ">= 1.5",
          harvester_reverse_max_m);
  require(harvester_lateral_m >= 0.0, "harvester_lateral_m", ">= 0", harvester_lateral_m);
  require(harvester_vibration_mps2 >= 0.0, "harvester_vibration_mps2", ">= 0",
          harvester_vibration_mps2);
  require(harvester_vibration_rate_deg_s >= 0.0, "harvester_vibration_rate_deg_s", ">= 0",
          harvester_vibration_rate_deg_s);
  require(harvester_vibration_min_hz > 0.0, "harvester_vibration_min_hz", "> 0",
          harvester_vibration_min_hz);
  require(harvester_vibration_max_hz >= harvester_vibration_min_hz, "harvester_vibration_max_hz",
          ">= harvester_vibration_min_hz", harvester_vibration_max_hz);
}

Motion::Motion(const MotionParams& params, double duration_s, std::uint64_t seed,
               Terrain terrain) {
  params.validate();
  model_ = params.model == MotionModel::kHarvester
               ? detail::makeHarvesterMotion(params, duration_s, seed, std::move(terrain))
               : detail::makeHandheldMotion(params, duration_s, seed, std::move(terrain));
}

Motion::~Motion() = default;
Motion::Motion(Motion&&) noexcept = default;
Motion& Motion::operator=(Motion&&) noexcept = default;

MotionState Motion::at(double t_s) const { return model_->at(t_s); }

std::vector<Eigen::Vector2d> Motion::loopPolyline(double spacing_m) const {
  return model_->pathPolyline(spacing_m);
}

double Motion::loopPeriod_s() const { return model_->loopPeriod_s(); }

std::vector<StandStill> Motion::standStills() const { return model_->standStills(); }

const HarvesterMachine* Motion::machine() const { return model_->machine(); }

Eigen::Vector2d Motion::loopCenter() const {
  const auto points = loopPolyline(1.0);
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return 0.5 * (lo + hi);
}

double Motion::loopHalfExtent_m() const {
  const auto points = loopPolyline(1.0);
  const Eigen::Vector2d center = loopCenter();
  double extent = 0.0;
  for (const auto& p : points) extent = std::max(extent, (p - center).cwiseAbs().maxCoeff());
  return extent;
}

}  // namespace taiga::sim
