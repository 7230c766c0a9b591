#pragma once
// The harvester's own body as lidar targets: the cabin, fixed in the body frame, and the crane
// (pillar, main boom, stick with telescope, harvester head), oriented boxes whose joint angles
// move smoothly: folded in front while driving, swung out to the side while a tree is felled and
// processed. The lidar intersects its rays with these boxes as well as with the forest (nearest
// hit wins), so the machine occludes part of every scan and returns points, as on a real machine.
//
// Body frame = IMU on the cabin roof, x forward, z up; the sensor sits on a mast 0.6 m above
// the roof.
// Dimensions roughly those of an 8-wheel harvester (Ponsse Scorpion / John Deere 1270 class).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/sim/motion.hpp"
#include "taiga/sim/scene.hpp"

namespace taiga::sim {

/// A box with centre, half-extents along its own axes, and orientation (box axes -> frame).
struct OrientedBox {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();

  /// Whether p (same frame as center) lies inside the box grown by margin_m.
  bool contains(const Eigen::Vector3d& p, double margin_m = 0.0) const;
};

/// Joint values of the crane.
struct BoomPose {
  double slew_rad = 0.0;       ///< rotation of the pillar about body z, + to the left
  double lift_rad = 0.0;       ///< main boom elevation above the body's xy plane
  double stick_rad = 0.0;      ///< stick elevation (negative: pointing down)
  double telescope_m = 0.0;    ///< stick extension
  double head_turn_rad = 0.0;  ///< rotation of the head about the vertical
};

/// The machine boxes placed in the world for one instant (one lidar column).
class MachineSnapshot {
 public:
  MachineSnapshot() = default;
  MachineSnapshot(const std::vector<OrientedBox>& boxes_body, const lie::SE3& T_world_body);
  /// Replaces `hit` by the nearest machine hit along origin + t dir, t in (0, t_max), when the
  /// machine is nearer (material kMachine, normal facing the ray).
  void occlude(const Eigen::Vector3d& origin_world, const Eigen::Vector3d& direction_world,
               double t_max_m, std::optional<RayHit>& hit) const;
  /// The same for rays that share an origin: hits[i] for directions[i].
  void occlude(const Eigen::Vector3d& origin_world,
               const std::vector<Eigen::Vector3d>& directions_world, double t_max_m,
               std::vector<std::optional<RayHit>>& hits) const;

 private:
  struct WorldBox {
    Eigen::Matrix3d R_world_box;
    Eigen::Vector3d center_world, half_extents;
  };
  std::vector<WorldBox> boxes_;
};

class HarvesterMachine {
 public:
  /// Box ids: 0 the cabin (fixed), then the moving parts.
  enum BoxId { kCabin = 0, kPillar, kMainBoom, kStick, kHead, kBoxCount };

  /// The crane swings out during each tree-handling stand-still and is folded otherwise.
  HarvesterMachine(const std::vector<StandStill>& stand_stills, std::uint64_t seed);

  /// The cabin box, body frame.
  static OrientedBox cabinInBody();
  BoomPose boomPose(double t_s) const;
  /// All boxes at time t, body frame, indexed by BoxId.
  std::vector<OrientedBox> boxesInBody(double t_s) const;
  /// Per box, a box (body frame) that encloses it over [t0_s, t1_s], grown by margin_m: the
  /// crop boxes of one scan. Index = BoxId.
  std::vector<OrientedBox> enclosingBoxesInBody(double t0_s, double t1_s, double margin_m) const;
  /// The boxes placed in the world at time t for a body pose.
  MachineSnapshot snapshot(double t_s, const lie::SE3& T_world_body) const {
    return MachineSnapshot(boxesInBody(t_s), T_world_body);
  }

 private:
  struct Work {
    double t0_s, ramp_s, hold_s;  ///< smooth plateau: boom out
    BoomPose target;
    double phases[4];
  };
  std::vector<Work> work_;
};

}  // namespace taiga::sim
