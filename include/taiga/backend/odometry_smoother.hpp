#pragma once
// The odometry graph (thesis 3.1.1, paper section 2): states x_k = (T_world_body, v_world, bias)
// at scan times, joined by preintegrated IMU factors (with the bias random walk) and anchored by
// lidar pose factors from scan-to-map registration.
//
// The smoother keeps a window of the latest states (fixed lag). When the window is full, the
// oldest state is dropped and what the graph knew about it is kept as a Gaussian prior on the
// next state: the marginal of the window's Gauss-Newton information at the solution (the Schur
// complement), so the cost per scan stays bounded and no information is thrown away beyond the
// linearization. A lag of 1 is an iterated extended Kalman filter; longer lags re-linearize the
// IMU factors of recent states when a late lidar factor moves them.
//
// The odom frame's tilt against gravity (state_blocks.hpp, kTiltSize) can be a further unknown
// shared by every IMU factor (initialize() with a tilt sigma; after FAST-LIO2, which keeps
// gravity in its state): the frame was levelled from 2 s of data, where a horizontal accelerometer
// bias and a tilt look alike, and once the rig turns the IMU tells them apart. With the tilt fixed,
// that late evidence could only turn the attitude away from the lidar's map, bending the map it
// builds (docs/odometry.md, Height); with it free, the map stays rigid and the tilt is measured.

#include <ceres/problem.h>

#include <array>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "taiga/backend/imu_factor.hpp"
#include "taiga/backend/state_blocks.hpp"
#include "taiga/imu/preintegration.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::backend {

struct OdometrySmootherOptions {
  Eigen::Vector3d gravity_world{0.0, 0.0, -9.81};
  /// States kept in the optimization window, >= 2.
  int window_states = 5;
  int max_iterations = 10;
};

struct StateEstimate {
  double t_s = 0.0;
  imu::NavState state;
  imu::ImuBias bias;
  /// Marginal covariance in the tangent order [dp; dtheta; dv; dba; dbg] (state_blocks.hpp).
  Matrix15 covariance = Matrix15::Identity();
};

/// A pose measurement of the newest state, e.g. from scan-to-map registration.
struct PoseMeasurement {
  lie::SE3 T_world_body;
  lie::Matrix6 covariance;  ///< in the SE(3) tangent [rho; theta] at T_world_body
};

class OdometrySmoother {
 public:
  explicit OdometrySmoother(OdometrySmootherOptions options = {});
  ~OdometrySmoother();

  /// Starts the graph with one state and its uncertainty, and the frame's tilt at `tilt` (zero
  /// at a start; what it was at a restart): with tilt_sigma_rad > 0 the tilt is estimated from
  /// then on under that prior 1-sigma, otherwise held (at zero: gravity is gravity_world).
  void initialize(const StateEstimate& first, double tilt_sigma_rad = 0.0,
                  const Eigen::Vector2d& tilt = Eigen::Vector2d::Zero());
  bool initialized() const { return !window_.empty(); }
  /// Forgets every state: initialized() is false until the next initialize().
  void reset();

  /// Adds a state at t_s, joined to the newest one by the IMU readings preintegrated since then
  /// (with the newest state's bias as bias_hat), with an optional pose measurement of it; then
  /// optimizes the window. Returns the new state's estimate.
  StateEstimate addState(double t_s, const imu::Preintegrator& preintegrated,
                         const std::optional<PoseMeasurement>& measurement);

  const StateEstimate& latest() const { return latest_; }
  /// The odom frame's tilt [theta_x; theta_y], rad (zero unless estimated), and gravity in the
  /// odom frame with it.
  Eigen::Vector2d tilt() const { return {tilt_[0], tilt_[1]}; }
  Eigen::Vector3d gravityWorld() const;

 private:
  struct Node;
  void optimize();
  void marginalizeOldest();
  /// Adds the tilt block to `problem`, and to the blocks to linearize when it is estimated
  /// (constant otherwise).
  void addTilt(ceres::Problem& problem, std::vector<double*>& linearized);

  bool estimatesTilt() const { return tilt_sigma_rad_ > 0.0; }
  /// Tangent size of what the marginalization keeps: the next state, and the tilt when estimated.
  Eigen::Index marginalSize() const { return 15 + (estimatesTilt() ? kTiltSize : 0); }

  OdometrySmootherOptions options_;
  std::deque<std::unique_ptr<Node>> window_;
  std::array<double, kTiltSize> tilt_{0.0, 0.0};
  double tilt_sigma_rad_ = 0.0;
  StateEstimate latest_;
};

}  // namespace taiga::backend
