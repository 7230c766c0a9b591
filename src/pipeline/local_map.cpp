#include "taiga/pipeline/local_map.hpp"

namespace taiga::pipeline {

LocalMap::LocalMap(double ndt_resolution_m, double point_spacing_m, int max_keyframes,
                   const registration::GicpConfig& gicp)
    : max_keyframes_(max_keyframes),
      gicp_config_(gicp),
      statistics_(ndt_resolution_m),
      point_statistics_(point_spacing_m) {}

void LocalMap::addKeyframe(std::vector<Eigen::Vector3d> points_in_world) {
  statistics_.add(points_in_world);
  point_statistics_.add(points_in_world);
  keyframes_.push_back(std::move(points_in_world));
  while (static_cast<int>(keyframes_.size()) > max_keyframes_) {
    statistics_.remove(keyframes_.front());
    point_statistics_.remove(keyframes_.front());
    keyframes_.pop_front();
  }
  ndt_target_.reset();
  kd_tree_.reset();
  gicp_cloud_.reset();
}

void LocalMap::transform(const lie::SE3& T_new_old) {
  statistics_.clear();
  point_statistics_.clear();
  for (auto& keyframe : keyframes_) {
    for (Eigen::Vector3d& p : keyframe) p = T_new_old * p;
    statistics_.add(keyframe);
    point_statistics_.add(keyframe);
  }
  ndt_target_.reset();
  kd_tree_.reset();
  gicp_cloud_.reset();
}

std::size_t LocalMap::numPoints() const {
  std::size_t n = 0;
  for (const auto& keyframe : keyframes_) n += keyframe.size();
  return n;
}

const registration::NdtTarget& LocalMap::ndtTarget() {
  if (!ndt_target_) ndt_target_ = std::make_unique<registration::NdtTarget>(statistics_);
  return *ndt_target_;
}

const registration::KdTree& LocalMap::kdTree() {
  if (!kd_tree_) kd_tree_ = std::make_unique<registration::KdTree>(point_statistics_.means());
  return *kd_tree_;
}

const registration::GicpCloud& LocalMap::gicpCloud() {
  if (!gicp_cloud_)
    gicp_cloud_ =
        std::make_unique<registration::GicpCloud>(point_statistics_.means(), gicp_config_);
  return *gicp_cloud_;
}

}  // namespace taiga::pipeline
