#include "taiga/backend/odometry_smoother.hpp"

#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>
#include <vector>

#include "taiga/backend/pose_factor.hpp"
#include "taiga/backend/state_prior.hpp"
#include "taiga/core/log.hpp"

namespace taiga::backend {

struct OdometrySmoother::Node {
  double t_s = 0.0;
  StateBlocks blocks;
  std::unique_ptr<ImuFactor> imu_from_previous;  ///< null for the oldest node
  std::unique_ptr<PoseFactor> pose;              ///< null without a measurement
  std::unique_ptr<StatePrior> prior;             ///< only on the oldest node
};

namespace {

const PoseManifold kPoseManifold;

ceres::Problem::Options borrowingOptions() {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = false;
  return options;
}

void addNode(ceres::Problem& problem, StateBlocks& blocks) {
  problem.AddParameterBlock(blocks.pose.data(), kPoseSize,
                            const_cast<PoseManifold*>(&kPoseManifold));
  problem.AddParameterBlock(blocks.motion.data(), kMotionSize);
}

/// Gauss-Newton information H = J^T J and gradient b = J^T r of `problem` over `blocks`, in
/// their tangent spaces.
void linearize(ceres::Problem& problem, const std::vector<double*>& blocks, Eigen::MatrixXd& H,
               Eigen::VectorXd& b) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  options.num_threads = 1;
  std::vector<double> residuals;
  ceres::CRSMatrix jacobian;
  problem.Evaluate(options, nullptr, &residuals, nullptr, &jacobian);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(jacobian.num_rows, jacobian.num_cols);
  for (int row = 0; row < jacobian.num_rows; ++row) {
    for (int k = jacobian.rows[row]; k < jacobian.rows[row + 1]; ++k)
      J(row, jacobian.cols[k]) = jacobian.values[k];
  }
  const Eigen::Map<const Eigen::VectorXd> r(residuals.data(),
                                            static_cast<Eigen::Index>(residuals.size()));
  H = J.transpose() * J;
  b = J.transpose() * r;
}

/// A prior that holds a state without constraining it much: 1 m, 0.1 rad, 1 m/s, 0.1 m/s^2,
/// 0.01 rad/s (1-sigma), in the tangent order [dp; dtheta; dv; dba; dbg].
Matrix15 weakCovariance() {
  Eigen::Matrix<double, 15, 1> sigma;
  sigma << Eigen::Vector3d::Constant(1.0), Eigen::Vector3d::Constant(0.1),
      Eigen::Vector3d::Constant(1.0), Eigen::Vector3d::Constant(0.1),
      Eigen::Vector3d::Constant(0.01);
  return sigma.cwiseAbs2().asDiagonal();
}

/// A state's covariance and the tilt's, independent; a tilt that is not estimated is held
/// constant and its (unit) variance never enters.
StatePrior::Covariance withTilt(const Matrix15& state, double tilt_sigma_rad) {
  const double variance = tilt_sigma_rad > 0.0 ? tilt_sigma_rad * tilt_sigma_rad : 1.0;
  StatePrior::Covariance covariance = StatePrior::Covariance::Zero();
  covariance.topLeftCorner<15, 15>() = state;
  covariance.bottomRightCorner<kTiltSize, kTiltSize>().diagonal().setConstant(variance);
  return covariance;
}

/// x (+) delta in the tangent order [dp; dtheta; dv; dba; dbg].
StateBlocks plus(const StateBlocks& x, const Eigen::Matrix<double, 15, 1>& delta) {
  StateBlocks moved = x;
  kPoseManifold.Plus(x.pose.data(), delta.data(), moved.pose.data());
  for (int i = 0; i < kMotionSize; ++i) moved.motion[i] += delta[6 + i];
  return moved;
}

}  // namespace

OdometrySmoother::OdometrySmoother(OdometrySmootherOptions options) : options_(options) {
  if (options_.window_states < 2)
    throw std::invalid_argument("OdometrySmoother: window_states must be at least 2");
}

OdometrySmoother::~OdometrySmoother() = default;

void OdometrySmoother::initialize(const StateEstimate& first, double tilt_sigma_rad,
                                  const Eigen::Vector2d& tilt) {
  window_.clear();
  auto node = std::make_unique<Node>();
  node->t_s = first.t_s;
  node->blocks = StateBlocks::from(first.state, first.bias);
  tilt_ = {tilt.x(), tilt.y()};
  tilt_sigma_rad_ = tilt_sigma_rad;
  node->prior = std::make_unique<StatePrior>(node->blocks, StatePrior::Tilt(tilt),
                                             withTilt(first.covariance, tilt_sigma_rad_));
  window_.push_back(std::move(node));
  latest_ = first;
}

StateEstimate OdometrySmoother::addState(double t_s, const imu::Preintegrator& preintegrated,
                                         const std::optional<PoseMeasurement>& measurement) {
  if (!initialized()) throw std::logic_error("OdometrySmoother::addState before initialize");
  const Node& newest = *window_.back();
  auto node = std::make_unique<Node>();
  node->t_s = t_s;
  // Initial guess: the IMU prediction from the newest state.
  const imu::ImuBias bias = newest.blocks.bias();
  node->blocks = StateBlocks::from(
      preintegrated.predict(newest.blocks.navState(), bias, gravityWorld()), bias);
  node->imu_from_previous = std::make_unique<ImuFactor>(preintegrated, options_.gravity_world);
  if (measurement)
    node->pose = std::make_unique<PoseFactor>(measurement->T_world_body, measurement->covariance);
  window_.push_back(std::move(node));
  if (static_cast<int>(window_.size()) > options_.window_states) marginalizeOldest();
  optimize();
  return latest_;
}

void OdometrySmoother::reset() { window_.clear(); }

Eigen::Vector3d OdometrySmoother::gravityWorld() const {
  return gravityFromTilt(tilt_.data(), options_.gravity_world);
}

void OdometrySmoother::addTilt(ceres::Problem& problem, std::vector<double*>& linearized) {
  problem.AddParameterBlock(tilt_.data(), kTiltSize);
  if (estimatesTilt()) {
    linearized.push_back(tilt_.data());
  } else {
    problem.SetParameterBlockConstant(tilt_.data());
  }
}

void OdometrySmoother::optimize() {
  ceres::Problem problem(borrowingOptions());
  // The tilt first, so that the newest state is the last 15 columns.
  std::vector<double*> blocks;
  addTilt(problem, blocks);
  for (std::size_t k = 0; k < window_.size(); ++k) {
    Node& node = *window_[k];
    addNode(problem, node.blocks);
    blocks.push_back(node.blocks.pose.data());
    blocks.push_back(node.blocks.motion.data());
    if (node.prior)
      problem.AddResidualBlock(node.prior.get(), nullptr, node.blocks.pose.data(),
                               node.blocks.motion.data(), tilt_.data());
    if (node.pose) problem.AddResidualBlock(node.pose.get(), nullptr, node.blocks.pose.data());
    if (k > 0 && node.imu_from_previous) {
      Node& previous = *window_[k - 1];
      problem.AddResidualBlock(node.imu_from_previous.get(), nullptr, previous.blocks.pose.data(),
                               previous.blocks.motion.data(), node.blocks.pose.data(),
                               node.blocks.motion.data(), tilt_.data());
    }
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options_.max_iterations;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  linearize(problem, blocks, H, b);
  const Node& newest = *window_.back();
  latest_.t_s = newest.t_s;
  latest_.state = newest.blocks.navState();
  latest_.bias = newest.blocks.bias();
  const Eigen::Index n = H.rows();
  // Not evaluable: the covariance is unknown, not garbage.
  if (n < marginalSize() || !H.allFinite()) {
    logger().warn(
        "odometry smoother: the window's factors were not finite at {:.3f} s; its "
        "covariance is reported as a weak prior's",
        newest.t_s);
    latest_.covariance = weakCovariance();
    return;
  }
  const Eigen::MatrixXd covariance = H.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  latest_.covariance = covariance.bottomRightCorner<15, 15>();
}

void OdometrySmoother::marginalizeOldest() {
  // The factors that touch the oldest state: its prior, its pose factor, the IMU factor to the
  // next.
  Node& oldest = *window_[0];
  Node& next = *window_[1];
  ceres::Problem problem(borrowingOptions());
  addNode(problem, oldest.blocks);
  addNode(problem, next.blocks);
  std::vector<double*> blocks{oldest.blocks.pose.data(), oldest.blocks.motion.data(),
                              next.blocks.pose.data(), next.blocks.motion.data()};
  addTilt(problem, blocks);
  if (oldest.prior)
    problem.AddResidualBlock(oldest.prior.get(), nullptr, oldest.blocks.pose.data(),
                             oldest.blocks.motion.data(), tilt_.data());
  if (oldest.pose) problem.AddResidualBlock(oldest.pose.get(), nullptr, oldest.blocks.pose.data());
  problem.AddResidualBlock(next.imu_from_previous.get(), nullptr, oldest.blocks.pose.data(),
                           oldest.blocks.motion.data(), next.blocks.pose.data(),
                           next.blocks.motion.data(), tilt_.data());
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
  linearize(problem, blocks, H, b);
  // Schur complement onto the next state and the tilt (when estimated): H' = H11 - H10 H00^-1
  // H01, b' = b1 - H10 H00^-1 b0.
  const Eigen::Index m = marginalSize();
  const bool evaluated = H.rows() == 15 + m;
  Eigen::MatrixXd H_marginal;
  Eigen::VectorXd b_marginal;
  if (evaluated) {
    const Eigen::LDLT<Eigen::MatrixXd> H00(H.topLeftCorner(15, 15));
    H_marginal =
        H.bottomRightCorner(m, m) - H.bottomLeftCorner(m, 15) * H00.solve(H.topRightCorner(15, m));
    b_marginal = b.tail(m) - H.bottomLeftCorner(m, 15) * H00.solve(b.head(15));
  }
  if (!evaluated || !H_marginal.allFinite() || !b_marginal.allFinite()) {
    // The factors could not be evaluated (a non-finite IMU factor, e.g. across a long gap in
    // the readings): the next state keeps a weak prior at its estimate instead of a broken one.
    logger().warn(
        "odometry smoother: the marginalized state's factors were not finite at {:.3f} "
        "s; the window keeps a weak prior instead",
        next.t_s);
    next.prior =
        std::make_unique<StatePrior>(next.blocks, Eigen::Map<const StatePrior::Tilt>(tilt_.data()),
                                     withTilt(weakCovariance(), tilt_sigma_rad_));
  } else {
    // The quadratic 1/2 d^T H' d + b'^T d is a Gaussian with mean next (+) (-H'^-1 b'). H' is
    // made symmetric and its eigenvalues floored at 1e-12 of the largest: when a direction lost
    // nearly all its information (a gap in the IMU readings, no lidar), the covariance would
    // otherwise span more than double precision and its inverse in StatePrior fail.
    H_marginal = 0.5 * (H_marginal + H_marginal.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(H_marginal);
    const double floor = 1e-12 * std::max(eigen.eigenvalues().maxCoeff(), 1e-300);
    const Eigen::VectorXd lambda = eigen.eigenvalues().cwiseMax(floor);
    const Eigen::MatrixXd& V = eigen.eigenvectors();
    const Eigen::VectorXd shift =
        -V * lambda.cwiseInverse().asDiagonal() * V.transpose() * b_marginal;
    Eigen::MatrixXd covariance = V * lambda.cwiseInverse().asDiagonal() * V.transpose();
    covariance = 0.5 * (covariance + covariance.transpose());
    // The prior's tilt is the estimate moved by its share of the shift; not estimated, it stays
    // constant and its variance is a placeholder.
    StatePrior::Tilt tilt_mean = Eigen::Map<const StatePrior::Tilt>(tilt_.data());
    StatePrior::Covariance prior_covariance;
    if (estimatesTilt()) {
      tilt_mean += shift.tail<kTiltSize>();
      prior_covariance = covariance;
    } else {
      prior_covariance = withTilt(covariance, 0.0);
    }
    next.prior = std::make_unique<StatePrior>(plus(next.blocks, shift.head<15>()), tilt_mean,
                                              prior_covariance);
  }
  next.imu_from_previous.reset();
  window_.pop_front();
}

}  // namespace taiga::backend
