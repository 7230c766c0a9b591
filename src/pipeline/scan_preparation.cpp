#include "scan_preparation.hpp"

#include "taiga/preprocess/crop.hpp"
#include "taiga/preprocess/deskew.hpp"

namespace taiga::pipeline {

ScanPreparation::ScanPreparation(const OdometryConfig& config, const RigConfig& rig)
    : min_range_m_(config.min_range_m),
      max_range_m_(config.max_range_m),
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

}  // namespace taiga::pipeline
