#include "taiga/mapping/pose_graph.hpp"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <array>
#include <limits>
#include <memory>
#include <stdexcept>

#include "taiga/backend/gnss_factor.hpp"
#include "taiga/backend/position_factor.hpp"
#include "taiga/backend/relative_pose_factor.hpp"
#include "taiga/backend/state_blocks.hpp"

namespace taiga::mapping {
namespace {

using PoseBlock = std::array<double, backend::kPoseSize>;

}  // namespace

PoseGraph::PoseGraph(const MappingConfig& config) : config_(config) {}

std::size_t PoseGraph::addKeyframe(const lie::SE3& T_odom_body, std::uint64_t segment) {
  const std::size_t index = odometry_poses_.size();
  if (index == 0) {
    poses_.push_back(T_odom_body);
    path_lengths_m_.push_back(0.0);
  } else {
    const lie::SE3 T_prev_this = odometry_poses_.back().inverse() * T_odom_body;
    poses_.push_back(poses_.back() * T_prev_this);
    path_lengths_m_.push_back(path_lengths_m_.back() + T_prev_this.translation().norm());
  }
  odometry_poses_.push_back(T_odom_body);
  segments_.push_back(segment);
  return index;
}

RelativePose PoseGraph::odometryBetween(std::size_t from, std::size_t to) const {
  const lie::SE3 T_from_to = odometry_poses_[from].inverse() * odometry_poses_[to];
  const double distance_m = T_from_to.translation().norm();
  const bool bridge = segments_[from] != segments_[to];
  const double sigma_m =
      bridge ? kBridgeSigma_m
             : config_.odometry_sigma_m + config_.odometry_sigma_m_per_m * distance_m;
  const double sigma_rad =
      bridge ? kBridgeSigma_rad
             : config_.odometry_sigma_rad + config_.odometry_sigma_rad_per_m * distance_m;
  lie::Vector6 variances;
  variances << lie::Vector3::Constant(sigma_m * sigma_m),
      lie::Vector3::Constant(sigma_rad * sigma_rad);
  return {from, to, T_from_to, variances.asDiagonal().toDenseMatrix()};
}

void PoseGraph::setEnuMap(const lie::SE3& T_enu_map) {
  std::array<double, backend::kEnuWorldSize> block{};
  backend::writeEnuWorldBlock(T_enu_map, block.data());
  T_enu_map_ = backend::enuWorldFromBlock(block.data());
  unsolved_ = unsolved_ || !gnss_.empty();
}

void PoseGraph::addGnss(const GnssObservation& observation) {
  if (!T_enu_map_) throw std::logic_error("PoseGraph::addGnss before setEnuMap");
  if (observation.keyframe >= size())
    throw std::logic_error("PoseGraph::addGnss: no such keyframe");
  gnss_.push_back(observation);
  unsolved_ = true;
}

std::vector<double> PoseGraph::gnssWhitenedResiduals() const {
  std::vector<double> norms;
  if (!T_enu_map_) return norms;
  std::array<double, backend::kEnuWorldSize> enu{};
  backend::writeEnuWorldBlock(*T_enu_map_, enu.data());
  for (const GnssObservation& g : gnss_) {
    PoseBlock pose{};
    backend::writePoseBlock(poses_[g.keyframe], pose.data());
    const backend::GnssFactor factor(g.d_body, g.p_enu, g.covariance_enu_m2);
    const double* parameters[] = {pose.data(), enu.data()};
    Eigen::Vector3d r;
    factor.Evaluate(parameters, r.data(), nullptr);
    norms.push_back(r.norm());
  }
  return norms;
}

void PoseGraph::addLoop(const RelativePose& loop) { loops_.push_back(loop); }

double PoseGraph::addLoopIfConsistent(const RelativePose& loop, double max_chi2) {
  PoseGraph trial = *this;
  trial.addLoop(loop);
  const double chi2 = 2.0 * (trial.optimize() - cost_);
  if (chi2 <= max_chi2) *this = std::move(trial);
  return chi2;
}

double PoseGraph::loopPairChi2(const RelativePose& first, const RelativePose& second) const {
  const std::size_t a = first.from, b = first.to, c = second.from, d = second.to;
  if (segments_[a] != segments_[c] || segments_[b] != segments_[d])
    return std::numeric_limits<double>::infinity();
  const RelativePose ac = odometryBetween(a, c), bd = odometryBetween(b, d);
  // Both ways from a to d: T_ab T_bd and T_ac T_cd. With every relative pose perturbed on the
  // right (T Exp(e)), the cycle C = T_bd^-1 T_ab^-1 T_ac T_cd moves by
  //   e_cd + Adj(T_cd^-1) e_ac - Adj(Y^-1) e_ab - Adj(C^-1) e_bd,   Y = T_ab^-1 T_ac T_cd.
  const lie::SE3& T_ab = first.T_from_to;
  const lie::SE3& T_cd = second.T_from_to;
  const lie::SE3 Y = T_ab.inverse() * ac.T_from_to * T_cd;
  const lie::SE3 C = bd.T_from_to.inverse() * Y;
  const lie::Matrix6 A_ac = T_cd.inverse().adjoint(), A_ab = Y.inverse().adjoint(),
                     A_bd = C.inverse().adjoint();
  const lie::Matrix6 covariance = second.covariance + A_ac * ac.covariance * A_ac.transpose() +
                                  A_ab * first.covariance * A_ab.transpose() +
                                  A_bd * bd.covariance * A_bd.transpose();
  const lie::Vector6 e = C.Log();
  return e.dot(covariance.ldlt().solve(e));
}

void PoseGraph::addPosition(std::size_t keyframe, const Eigen::Vector3d& p_map,
                            const Eigen::Matrix3d& covariance, double huber_sigmas) {
  positions_.push_back({keyframe, p_map, covariance, huber_sigmas});
}

void PoseGraph::rotateMap(const lie::SO3& R_new_old) {
  const lie::SE3 T_new_old(R_new_old, Eigen::Vector3d::Zero());
  for (lie::SE3& pose : poses_) pose = T_new_old * pose;
  for (Position& position : positions_) {
    position.p_map = R_new_old * position.p_map;
    position.covariance = R_new_old.matrix() * position.covariance * R_new_old.matrix().transpose();
  }
  if (T_enu_map_) setEnuMap(*T_enu_map_ * T_new_old.inverse());
}

double PoseGraph::optimize() {
  if (size() < 2) return 0.0;
  std::vector<PoseBlock> blocks;
  blocks.reserve(size());
  for (const lie::SE3& pose : poses_) backend::writePoseBlock(pose, blocks.emplace_back().data());

  // The problem owns the factors and the loss functions; the manifold is shared.
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  backend::PoseManifold manifold;
  for (PoseBlock& block : blocks)
    problem.AddParameterBlock(block.data(), backend::kPoseSize, &manifold);
  auto addRelative = [&](const RelativePose& relative) {
    problem.AddResidualBlock(
        new backend::RelativePoseFactor(relative.T_from_to, relative.covariance), nullptr,
        blocks[relative.from].data(), blocks[relative.to].data());
  };
  for (std::size_t k = 1; k < size(); ++k) addRelative(odometryBetween(k - 1, k));
  for (const RelativePose& loop : loops_) addRelative(loop);
  for (const Position& position : positions_) {
    ceres::LossFunction* loss =
        position.huber_sigmas > 0.0 ? new ceres::HuberLoss(position.huber_sigmas) : nullptr;
    problem.AddResidualBlock(new backend::PositionFactor(position.p_map, position.covariance), loss,
                             blocks[position.keyframe].data());
  }
  // The ENU block is free in yaw and translation; see the header for the gauge.
  std::array<double, backend::kEnuWorldSize> enu{};
  if (!gnss_.empty()) {
    backend::writeEnuWorldBlock(*T_enu_map_, enu.data());
    problem.AddParameterBlock(enu.data(), backend::kEnuWorldSize);
    for (const GnssObservation& g : gnss_) {
      ceres::LossFunction* robust =
          g.huber_sigmas > 0.0 ? new ceres::HuberLoss(g.huber_sigmas) : nullptr;
      ceres::LossFunction* loss =
          g.weight == 1.0 ? robust : new ceres::ScaledLoss(robust, g.weight, ceres::TAKE_OWNERSHIP);
      problem.AddResidualBlock(new backend::GnssFactor(g.d_body, g.p_enu, g.covariance_enu_m2),
                               loss, blocks[g.keyframe].data(), enu.data());
    }
  }
  if (positions_.empty()) problem.SetParameterBlockConstant(blocks.front().data());

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = 50;
  options.num_threads = 1;  // the same answer every time
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (std::size_t k = 0; k < size(); ++k) poses_[k] = backend::poseFromBlock(blocks[k].data());
  if (!gnss_.empty()) T_enu_map_ = backend::enuWorldFromBlock(enu.data());
  unsolved_ = false;
  cost_ = summary.final_cost;
  return cost_;
}

}  // namespace taiga::mapping
