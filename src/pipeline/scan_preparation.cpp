#include "scan_preparation.hpp"

#include "taiga/preprocess/crop.hpp"
#include "taiga/preprocess/deskew.hpp"

namespace taiga::pipeline {

ScanPreparation::ScanPreparation(const OdometryConfig& config, const RigConfig& rig)
    : min_range_m_(config.min_range_m),
      max_range_m_(config.max_range_m),
      local_map_voxel_m_(config.local_map_voxel_m),
      local_map_point_(preprocess::voxelRepresentative(config.local_map_point)),
      T_body_lidar_(rig.T_body_lidar) {
  const lie::SE3 T_lidar_body = T_body_lidar_.inverse();
  for (const Box& box : rig.self_boxes_body)
    self_boxes_lidar_.push_back(OrientedBox::fromBox(box).expressedIn(T_lidar_body));
}

// The rig is rigid with the body, so a point is tested against the boxes at its own firing time,
// before deskewing: exact for any motion during the sweep.
PointCloud ScanPreparation::forestPointsInLidar(const io::Scan& scan) const {
  std::vector<OrientedBox> boxes_lidar = self_boxes_lidar_;
  const lie::SE3 T_lidar_body = T_body_lidar_.inverse();
  for (const OrientedBox& box_body : moving_boxes_body_.forScan(scan.t_start_s, scan.t_end_s))
    boxes_lidar.push_back(box_body.expressedIn(T_lidar_body));
  return preprocess::keepRangeOutsideBoxes(scan.cloud_in_lidar, min_range_m_, max_range_m_,
                                           boxes_lidar);
}

PointCloud ScanPreparation::deskewedInBody(const io::Scan& scan,
                                           const Trajectory& sweep_T_odom_body) const {
  return preprocess::deskew(forestPointsInLidar(scan), T_body_lidar_, sweep_T_odom_body,
                            scan.t_end_s)
      .cloud_in_body;
}

std::vector<Eigen::Vector3d> ScanPreparation::localMapPoints(
    const PointCloud& cloud_in_body) const {
  // The lidar's position at the scan's end stands for its positions over the sweep: a bearing
  // moves by at most the sweep's travel over the range, which picks a neighbour of the same
  // surface, not a point off it.
  return preprocess::voxelFilter(cloud_in_body, local_map_voxel_m_, local_map_point_,
                                 T_body_lidar_.translation())
      .positions;
}

}  // namespace taiga::pipeline
