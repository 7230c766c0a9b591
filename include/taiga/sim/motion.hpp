#pragma once
// Ground-truth motion of the sensor rig, chosen by MotionParams::model:
//
// - handheld: a person walks the scanner on a stick along a closed path over the terrain (one
//   loop, or a cloverleaf of lobes through the start area), so the walk returns to its start and
//   loop closure can be tested; with speed changes, pauses (the speed goes smoothly to zero and
//   back), heading swings of a person looking around, occasional fast turns up to about 90 deg/s,
//   gait bob and sway (see handheld_motion.cpp);
// - harvester: a forest harvester on the strip road, driving slowly from tree to tree, stopping
//   20-60 s to fell and process each, sometimes backing up, following the terrain under its
//   wheels, shaking in bursts while a tree is handled; its cabin and boom are geometry the lidar
//   sees (machine()) (see harvester_motion.cpp, machine.hpp).
//
// Everything is an analytic, twice differentiable function of time, so pose, velocity,
// acceleration and angular rate are exact at any time and the simulated IMU is consistent with
// the trajectory to machine precision.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "taiga/lie/se3.hpp"
#include "taiga/sim/scenario.hpp"
#include "taiga/sim/terrain.hpp"

namespace taiga::sim {

class HarvesterMachine;

struct MotionState {
  double t_s = 0.0;
  lie::SE3 T_world_body;
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();     ///< m/s
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();     ///< m/s^2 (kinematic, without gravity)
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();  ///< rad/s, in the body frame
};

/// A time in which the rig does not travel: its travel speed is exactly zero from `start_s` to
/// `end_s` (it slows down before and speeds up after, over the ramp time). The stick still sways
/// and the operator looks around; the harvester shakes while it handles a tree.
struct StandStill {
  enum class Kind { kPause, kTreeHandling, kManoeuvre };
  double start_s = 0.0;
  double end_s = 0.0;
  Kind kind = Kind::kPause;
};

namespace detail {
class TrajectoryModel;
}

class Motion {
 public:
  /// The handheld path is sized so that it is walked once in about 95 % of `duration_s` (at
  /// least 25 m long, at most params.max_loop_length_m; longer recordings repeat it). The
  /// harvester's schedule covers the duration. InputError for invalid params (params.validate()).
  Motion(const MotionParams& params, double duration_s, std::uint64_t seed, Terrain terrain);
  ~Motion();
  Motion(Motion&&) noexcept;
  Motion& operator=(Motion&&) noexcept;

  /// The exact state at time t_s (seconds since the start of the recording; any t_s >= 0).
  MotionState at(double t_s) const;

  /// The travelled path (handheld: the loop or cloverleaf; harvester: the road's centre line
  /// over the driven stretch) as closely spaced horizontal points (world frame), kept free of
  /// stems by the forest generator.
  std::vector<Eigen::Vector2d> loopPolyline(double spacing_m = 0.5) const;
  /// Centre of the path's bounding square and its half size, m.
  Eigen::Vector2d loopCenter() const;
  double loopHalfExtent_m() const;
  /// Handheld: the time at which the walk is back at its start for the first time, s (pauses
  /// included). Harvester: the duration (it does not return).
  double loopPeriod_s() const;
  /// Pauses of the operator, or stops of the harvester, in time order.
  std::vector<StandStill> standStills() const;
  /// The harvester's cabin and boom (geometry in the body frame), or nullptr for a handheld rig.
  const HarvesterMachine* machine() const;

 private:
  std::unique_ptr<detail::TrajectoryModel> model_;
};

/// The former name of Motion, from when the walk was the only model.
using WalkingMotion = Motion;

namespace detail {
/// What a motion model provides; Motion forwards to it.
class TrajectoryModel {
 public:
  virtual ~TrajectoryModel() = default;
  virtual MotionState at(double t_s) const = 0;
  virtual std::vector<Eigen::Vector2d> pathPolyline(double spacing_m) const = 0;
  virtual double loopPeriod_s() const = 0;
  virtual std::vector<StandStill> standStills() const = 0;
  virtual const HarvesterMachine* machine() const { return nullptr; }
};
}  // namespace detail

}  // namespace taiga::sim
