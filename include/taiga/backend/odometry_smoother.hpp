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

#include <deque>
#include <memory>
#include <optional>

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

  /// Starts the graph with one state and its uncertainty.
  void initialize(const StateEstimate& first);
  bool initialized() const { return !window_.empty(); }

  /// Adds a state at t_s, joined to the newest one by the IMU readings preintegrated since then
  /// (with the newest state's bias as bias_hat), with an optional pose measurement of it; then
  /// optimizes the window. Returns the new state's estimate.
  StateEstimate addState(double t_s, const imu::Preintegrator& preintegrated,
                         const std::optional<PoseMeasurement>& measurement);

  const StateEstimate& latest() const { return latest_; }

 private:
  struct Node;
  void optimize();
  void marginalizeOldest();

  OdometrySmootherOptions options_;
  std::deque<std::unique_ptr<Node>> window_;
  StateEstimate latest_;
};

}  // namespace taiga::backend
