// The harvester's cabin and crane as oriented boxes (see machine.hpp), and rays against them.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "smooth.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/sim/machine.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {
constexpr double kPi = std::numbers::pi;

// Crane geometry, body frame (m): the pillar stands on the front frame ahead of the cabin.
const Eigen::Vector3d kPillarBase_body(1.8, 0.0, -2.2);
const Eigen::Vector3d kBoomPivot_body(1.8, 0.0, -1.0);
constexpr double kMainBoomLength_m = 4.5;
constexpr double kStickLength_m = 3.8;
constexpr double kHeadDrop_m = 0.6;  ///< head centre below the stick tip

/// Folded for driving: boom up, stick down in front, head above the front frame.
constexpr BoomPose kRestPose{0.0, 35.0 * kRadPerDeg, -80.0 * kRadPerDeg, 0.0, 0.0};

Eigen::Quaterniond rotZ(double a) { return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ())); }
Eigen::Quaterniond rotY(double a) { return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY())); }

/// Slab test (Kay and Kajiya): entry distance of origin + t dir into the axis-aligned box
/// [-h, h] and the axis of the entry face (sign in *sign); nothing for a miss, an origin inside,
/// or an entry beyond t_max.
std::optional<double> slabEntry(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                const Eigen::Vector3d& h, double t_max, int* axis, double* sign) {
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (std::abs(o[i]) > h[i]) return std::nullopt;
      continue;
    }
    double t1 = (-h[i] - o[i]) / d[i], t2 = (h[i] - o[i]) / d[i];
    double s = -1.0;  // entering through the -h face when moving in +i
    if (t1 > t2) std::swap(t1, t2), s = 1.0;
    if (t1 > t_near) t_near = t1, *axis = i, *sign = s;
    t_far = std::min(t_far, t2);
  }
  if (t_near > t_far || t_near <= 0.0 || t_near >= t_max) return std::nullopt;
  return t_near;
}
}  // namespace

bool OrientedBox::contains(const Eigen::Vector3d& p, double margin_m) const {
  const Eigen::Vector3d q = orientation.conjugate() * (p - center);
  return (q.cwiseAbs().array() <= half_extents.array() + margin_m).all();
}

MachineSnapshot::MachineSnapshot(const std::vector<OrientedBox>& boxes_body,
                                 const lie::SE3& T_world_body) {
  const Eigen::Matrix3d R_world_body = T_world_body.rotation().matrix();
  for (const OrientedBox& b : boxes_body) {
    boxes_.push_back({R_world_body * b.orientation.toRotationMatrix(), T_world_body * b.center,
                      b.half_extents});
  }
}

void MachineSnapshot::occlude(const Eigen::Vector3d& origin_world,
                              const Eigen::Vector3d& direction_world, double t_max_m,
                              std::optional<RayHit>& hit) const {
  double nearest = hit ? std::min(hit->range_m, t_max_m) : t_max_m;
  for (const WorldBox& b : boxes_) {
    const Eigen::Vector3d o = b.R_world_box.transpose() * (origin_world - b.center_world);
    const Eigen::Vector3d d = b.R_world_box.transpose() * direction_world;
    int axis = 0;
    double sign = 1.0;
    const auto t = slabEntry(o, d, b.half_extents, nearest, &axis, &sign);
    if (!t) continue;
    nearest = *t;
    hit = RayHit{*t, sign * b.R_world_box.col(axis), Material::kMachine};
  }
}

void MachineSnapshot::occlude(const Eigen::Vector3d& origin_world,
                              const std::vector<Eigen::Vector3d>& directions_world,
                              double t_max_m, std::vector<std::optional<RayHit>>& hits) const {
  for (std::size_t i = 0; i < directions_world.size(); ++i)
    occlude(origin_world, directions_world[i], t_max_m, hits[i]);
}

HarvesterMachine::HarvesterMachine(const std::vector<StandStill>& stand_stills,
                                   std::uint64_t seed) {
  Rng rng(streamSeed(seed, "harvester-crane"));
  for (const StandStill& s : stand_stills) {
    if (s.kind != StandStill::Kind::kTreeHandling) continue;
    // Out after the machine has stopped, folded again before it drives on.
    Work w;
    w.ramp_s = 4.0;
    w.t0_s = s.start_s + 1.0;
    w.hold_s = std::max(0.0, s.end_s - s.start_s - 2.0 - 2.0 * w.ramp_s);
    const double side = rng.bernoulli(0.5) ? 1.0 : -1.0;
    w.target = BoomPose{side * rng.uniform(60.0, 110.0) * kRadPerDeg,
                        rng.uniform(5.0, 25.0) * kRadPerDeg, rng.uniform(-65.0, -40.0) * kRadPerDeg,
                        rng.uniform(0.5, 1.8), rng.uniform(-90.0, 90.0) * kRadPerDeg};
    for (double& p : w.phases) p = rng.uniform(0.0, 2.0 * kPi);
    work_.push_back(w);
  }
}

OrientedBox HarvesterMachine::cabinInBody() {
  // 2 m x 1.9 m x 2 m, its roof 0.6 m below the sensor (on a short mast, so that the roof
  // fills less of the lidar's lower field of view).
  return {Eigen::Vector3d(0.0, 0.0, -1.6), Eigen::Vector3d(1.0, 0.95, 1.0),
          Eigen::Quaterniond::Identity()};
}

BoomPose HarvesterMachine::boomPose(double t) const {
  BoomPose pose = kRestPose;
  for (const Work& w : work_) {
    const detail::Plateau plateau{w.t0_s, w.ramp_s, w.hold_s, 1.0};
    const double e = plateau.value(t).v;
    if (e == 0.0) continue;
    // Towards the working pose, with slow motions of the operator on top (felling, feeding).
    pose.slew_rad += e * (w.target.slew_rad - kRestPose.slew_rad +
                          10.0 * kRadPerDeg * std::sin(2.0 * kPi * 0.05 * t + w.phases[0]));
    pose.lift_rad += e * (w.target.lift_rad - kRestPose.lift_rad +
                          6.0 * kRadPerDeg * std::sin(2.0 * kPi * 0.08 * t + w.phases[1]));
    pose.stick_rad += e * (w.target.stick_rad - kRestPose.stick_rad +
                           10.0 * kRadPerDeg * std::sin(2.0 * kPi * 0.11 * t + w.phases[2]));
    pose.telescope_m += e * (w.target.telescope_m - kRestPose.telescope_m);
    pose.head_turn_rad += e * (w.target.head_turn_rad +
                               30.0 * kRadPerDeg * std::sin(2.0 * kPi * 0.07 * t + w.phases[3]));
  }
  return pose;
}

std::vector<OrientedBox> HarvesterMachine::boxesInBody(double t) const {
  const BoomPose p = boomPose(t);
  const Eigen::Quaterniond slew = rotZ(p.slew_rad);
  std::vector<OrientedBox> boxes(kBoxCount);
  boxes[kCabin] = cabinInBody();
  boxes[kPillar] = {kPillarBase_body + Eigen::Vector3d(0, 0, 0.6), Eigen::Vector3d(0.3, 0.3, 0.6),
                    slew};
  // Ry(-a) turns the box's x axis up by a.
  const Eigen::Vector3d boom_dir = slew * Eigen::Vector3d(std::cos(p.lift_rad), 0.0, std::sin(p.lift_rad));
  const Eigen::Vector3d boom_tip = kBoomPivot_body + kMainBoomLength_m * boom_dir;
  boxes[kMainBoom] = {kBoomPivot_body + 0.5 * kMainBoomLength_m * boom_dir,
                      Eigen::Vector3d(0.5 * kMainBoomLength_m + 0.15, 0.18, 0.25),
                      slew * rotY(-p.lift_rad)};
  const double stick_length = kStickLength_m + p.telescope_m;
  const Eigen::Vector3d stick_dir =
      slew * Eigen::Vector3d(std::cos(p.stick_rad), 0.0, std::sin(p.stick_rad));
  const Eigen::Vector3d stick_tip = boom_tip + stick_length * stick_dir;
  boxes[kStick] = {boom_tip + 0.5 * stick_length * stick_dir,
                   Eigen::Vector3d(0.5 * stick_length + 0.12, 0.14, 0.2),
                   slew * rotY(-p.stick_rad)};
  boxes[kHead] = {stick_tip - Eigen::Vector3d(0.0, 0.0, kHeadDrop_m),
                  Eigen::Vector3d(0.35, 0.45, 0.6), rotZ(p.slew_rad + p.head_turn_rad)};
  for (OrientedBox& b : boxes) b.orientation.normalize();
  return boxes;
}

std::vector<OrientedBox> HarvesterMachine::enclosingBoxesInBody(double t0, double t1,
                                                                double margin_m) const {
  // Sample the motion densely (every <= 5 ms; the crane tip moves < 1 cm in that time) and
  // enclose every sampled box's corners in a box with the orientation of the middle sample.
  const int samples = std::max(3, static_cast<int>(std::ceil((t1 - t0) / 0.005)) + 1);
  std::vector<std::vector<OrientedBox>> sampled;
  for (int k = 0; k < samples; ++k) sampled.push_back(boxesInBody(t0 + (t1 - t0) * k / (samples - 1)));
  std::vector<OrientedBox> out = sampled[samples / 2];
  for (int id = 0; id < kBoxCount; ++id) {
    OrientedBox& box = out[id];
    const Eigen::Quaterniond q_inv = box.orientation.conjugate();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const auto& boxes : sampled) {
      const OrientedBox& b = boxes[id];
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d s((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0,
                                (corner & 4) ? 1.0 : -1.0);
        const Eigen::Vector3d p = q_inv * (b.center + b.orientation * s.cwiseProduct(b.half_extents));
        lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      }
    }
    box.center = box.orientation * (0.5 * (lo + hi));
    box.half_extents = 0.5 * (hi - lo) + Eigen::Vector3d::Constant(margin_m);
  }
  return out;
}

}  // namespace taiga::sim
