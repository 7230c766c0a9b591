// The harvester on the strip road (world x axis). A schedule drawn from the seed: drive forward
// 4-12 m at 0.3-1 m/s, stop 20-60 s to fell and process a tree, sometimes back up 1.5-4 m and
// stop briefly, drive on. The distance along the road is s(t) = sum_i v_i integral P_i (smooth
// plateaus of signed speed: C2, exactly zero speed while stopped). On the road the machine weaves
// slowly, y(s) = a (sin(k s + phase) - sin(phase)), heading psi = atan(y'(s)) (the machine points
// along its track, also when reversing). Its four bogie contact points follow the smooth terrain:
//   pitch = -atan((h_front - h_rear) / wheelbase), roll = atan((h_left - h_right) / track),
// so roll and pitch are the terrain's slope averaged over the 4.4 m x 2.3 m footprint. The
// sensor sits sensor_height_m above the footprint's mean height along the machine's up axis (so
// it sways with roll and pitch). While a tree is handled, vibration bursts (C2 envelopes, sums of
// 10-30 Hz sines) shake the body in translation and rotation.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "motion_models.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/sim/machine.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim::detail {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kHalfWheelbase_m = 2.2;
constexpr double kHalfTrack_m = 1.15;
constexpr double kStartStill_s = 3.0;  ///< standing with the engine running before the first drive
constexpr double kVibrationRamp_s = 0.3;
constexpr int kVibrationSines = 3;

class HarvesterMotion final : public TrajectoryModel {
 public:
  HarvesterMotion(const MotionParams& params, double duration_s, std::uint64_t seed,
                  Terrain terrain);

  MotionState at(double t) const override;
  std::vector<Eigen::Vector2d> pathPolyline(double spacing_m) const override;
  double loopPeriod_s() const override { return duration_s_; }
  std::vector<StandStill> standStills() const override { return stand_stills_; }
  const HarvesterMachine* machine() const override { return machine_.get(); }

 private:
  struct Sine {
    double amplitude, frequency_hz, phase;
  };
  void drawSchedule(std::uint64_t seed);
  void drawVibration(std::uint64_t seed);
  /// Lateral offset y(s) on the road and its derivatives with respect to s (up to the third).
  void lateral(double s, double* y, double* dy, double* ddy, double* dddy) const;

  MotionParams params_;
  double duration_s_;
  Terrain terrain_;
  PlateauTrain drives_;  ///< weights: signed speeds, m/s
  PlateauTrain bursts_;  ///< weights: vibration intensity 0..1
  std::vector<StandStill> stand_stills_;
  double weave_k_ = 0.1, weave_phase_ = 0.0;
  /// Per axis: x, y, z translation (m) and roll, pitch, yaw (rad).
  Sine vibration_[6][kVibrationSines]{};
  std::unique_ptr<HarvesterMachine> machine_;
};

HarvesterMotion::HarvesterMotion(const MotionParams& params, double duration_s,
                                 std::uint64_t seed, Terrain terrain)
    : params_(params), duration_s_(duration_s), terrain_(std::move(terrain)) {
  drawSchedule(seed);
  drawVibration(seed);
  machine_ = std::make_unique<HarvesterMachine>(stand_stills_, seed);
}

void HarvesterMotion::drawSchedule(std::uint64_t seed) {
  const MotionParams& p = params_;
  Rng rng(streamSeed(seed, "harvester"));
  weave_k_ = 2.0 * kPi / rng.uniform(30.0, 60.0);
  weave_phase_ = rng.uniform(0.0, 2.0 * kPi);
  std::vector<Plateau> drives, bursts;
  double t = kStartStill_s;
  auto drive = [&](double distance_m, double speed_mps) {
    Plateau d;
    d.t0_s = t;
    d.ramp_s = std::min(p.harvester_ramp_s, 0.5 * std::abs(distance_m / speed_mps));
    d.hold_s = std::abs(distance_m / speed_mps) - d.ramp_s;  // area = ramp + hold
    d.weight = speed_mps;
    drives.push_back(d);
    t = d.end_s();
  };
  while (t < duration_s_ + 30.0) {
    drive(rng.uniform(p.harvester_drive_min_m, p.harvester_drive_max_m),
          rng.uniform(p.harvester_speed_min_mps, p.harvester_speed_max_mps));
    const double stop_s = rng.uniform(p.harvester_stop_min_s, p.harvester_stop_max_s);
    stand_stills_.push_back({t, t + stop_s, StandStill::Kind::kTreeHandling});
    // The crane is out from 5 s after the stop until 5 s before its end (harvester_machine.cpp):
    // the felling cut first, then bursts of feeding and delimbing.
    const double work_end = t + stop_s - 5.5;
    double b = t + 5.5;
    bool felling = true;
    while (b + 1.5 < work_end) {
      Plateau burst;
      burst.t0_s = b;
      burst.ramp_s = kVibrationRamp_s;
      burst.hold_s =
          std::min(felling ? rng.uniform(2.0, 4.0) : rng.uniform(2.0, 6.0), work_end - b - 0.6);
      burst.weight = rng.uniform(0.6, 1.0);
      bursts.push_back(burst);
      b = burst.end_s() + rng.uniform(1.0, 4.0);
      felling = false;
    }
    t += stop_s;
    if (rng.bernoulli(p.harvester_reverse_probability)) {
      const double speed = rng.uniform(p.harvester_speed_min_mps,
                                       std::min(0.5, p.harvester_speed_max_mps));
      drive(-rng.uniform(1.5, p.harvester_reverse_max_m), -speed);
      const double wait_s = rng.uniform(3.0, 6.0);
      stand_stills_.push_back({t, t + wait_s, StandStill::Kind::kManoeuvre});
      t += wait_s;
    }
  }
  drives_ = PlateauTrain(std::move(drives));
  bursts_ = PlateauTrain(std::move(bursts));
}

void HarvesterMotion::drawVibration(std::uint64_t seed) {
  const MotionParams& p = params_;
  Rng rng(streamSeed(seed, "harvester-vibration"));
  for (int axis = 0; axis < 6; ++axis) {
    for (Sine& s : vibration_[axis]) {
      s.frequency_hz = rng.uniform(p.harvester_vibration_min_hz, p.harvester_vibration_max_hz);
      s.phase = rng.uniform(0.0, 2.0 * kPi);
      const double w = 2.0 * kPi * s.frequency_hz;
      // Each sine carries a third of the peak: acceleration A w^2, angular rate A w.
      if (axis < 3) {
        const double peak = p.harvester_vibration_mps2 * (axis == 2 ? 1.5 : 1.0);
        s.amplitude = peak / kVibrationSines / (w * w) * rng.uniform(0.7, 1.0);
      } else {
        s.amplitude = p.harvester_vibration_rate_deg_s * kRadPerDeg / kVibrationSines / w *
                      rng.uniform(0.7, 1.0);
      }
    }
  }
}

void HarvesterMotion::lateral(double s, double* y, double* dy, double* ddy, double* dddy) const {
  const double a = params_.harvester_lateral_m, k = weave_k_;
  const double sn = std::sin(k * s + weave_phase_), cs = std::cos(k * s + weave_phase_);
  *y = a * (sn - std::sin(weave_phase_));
  *dy = a * k * cs;
  *ddy = -a * k * k * sn;
  *dddy = -a * k * k * k * cs;
}

MotionState HarvesterMotion::at(double t) const {
  const Jet s = drives_.integral(t);  // distance along the road
  double y0, dy, ddy, dddy;
  lateral(s.v, &y0, &dy, &ddy, &dddy);
  const Jet x = s;
  const Jet y = chain(y0, dy, ddy, s);
  const Jet yaw = atan(chain(dy, ddy, dddy, s));
  const Jet cy = cos(yaw), sy = sin(yaw);

  // Ground under the bogies (front/rear x left/right).
  Jet h[2][2];
  for (int f = 0; f < 2; ++f) {
    for (int l = 0; l < 2; ++l) {
      const double ox = f == 0 ? kHalfWheelbase_m : -kHalfWheelbase_m;
      const double oy = l == 0 ? kHalfTrack_m : -kHalfTrack_m;
      h[f][l] = groundUnder(terrain_, x + ox * cy - oy * sy, y + ox * sy + oy * cy);
    }
  }
  const Jet ground = 0.25 * (h[0][0] + h[0][1] + h[1][0] + h[1][1]);
  const Jet pitch = -atan((0.25 / kHalfWheelbase_m) * (h[0][0] + h[0][1] - h[1][0] - h[1][1]));
  const Jet roll = atan((0.25 / kHalfTrack_m) * (h[0][0] + h[1][0] - h[0][1] - h[1][1]));

  // Up axis of R = Rz(yaw) Ry(pitch) Rx(roll): (cy sp cr + sy sr, sy sp cr - cy sr, cp cr).
  const Jet sp = sin(pitch), cp = cos(pitch), sr = sin(roll), cr = cos(roll);
  const double H = params_.sensor_height_m;
  Jet px = x + H * (cy * sp * cr + sy * sr);
  Jet py = y + H * (sy * sp * cr - cy * sr);
  Jet pz = ground + H * (cp * cr);

  // Vibration bursts while a tree is handled.
  const Jet envelope = bursts_.value(t);
  Jet shake[6];
  if (envelope.v != 0.0 || envelope.d != 0.0) {
    for (int axis = 0; axis < 6; ++axis) {
      Jet sum;
      for (const Sine& v : vibration_[axis]) sum = sum + sineJet(v.amplitude, v.frequency_hz, v.phase, t);
      shake[axis] = envelope * sum;
    }
  }
  px = px + shake[0], py = py + shake[1], pz = pz + shake[2];

  MotionState state;
  state.t_s = t;
  lie::SO3 R;
  eulerOrientation(roll + shake[3], pitch + shake[4], yaw + shake[5], &R, &state.omega_body);
  state.T_world_body = lie::SE3(R, Eigen::Vector3d(px.v, py.v, pz.v));
  state.v_world = Eigen::Vector3d(px.d, py.d, pz.d);
  state.a_world = Eigen::Vector3d(px.dd, py.dd, pz.dd);
  return state;
}

std::vector<Eigen::Vector2d> HarvesterMotion::pathPolyline(double spacing_m) const {
  // The road's centre line (y = 0) over the stretch driven during the recording.
  double lo = 0.0, hi = 0.0;
  for (double t = 0.0; t <= duration_s_; t += 0.5) {
    const double s = drives_.integral(t).v;
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  lo -= 5.0, hi += 5.0;
  std::vector<Eigen::Vector2d> points;
  for (double x = lo; x <= hi; x += spacing_m) points.emplace_back(x, 0.0);
  return points;
}
}  // namespace

std::unique_ptr<TrajectoryModel> makeHarvesterMotion(const MotionParams& params,
                                                     double duration_s, std::uint64_t seed,
                                                     Terrain terrain) {
  return std::make_unique<HarvesterMotion>(params, duration_s, seed, std::move(terrain));
}

}  // namespace taiga::sim::detail
