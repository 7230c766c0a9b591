#pragma once
// Step 2 of the odometry (thesis 3.1.1) for one scan: the returns that belong to the forest
// (within the range limits, outside the rig's own boxes), deskewed into the body frame at the
// scan's end with the poses a motion prior gives over the sweep (thesis Eq. 34-35). Internal to
// the pipeline.

#include <vector>

#include "taiga/core/box.hpp"
#include "taiga/core/odometry_config.hpp"
#include "taiga/core/point_cloud.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/preprocess/voxel_filter.hpp"

namespace taiga::pipeline {

class ScanPreparation {
 public:
  ScanPreparation(const OdometryConfig& config, const RigConfig& rig);

  /// Boxes around moving parts of the rig (a harvester's boom), per scan, in the body frame.
  void setMovingBoxes(MovingBoxes boxes_body) { moving_boxes_body_ = std::move(boxes_body); }

  /// The scan's forest returns, deskewed with `sweep_T_odom_body` (poses covering the sweep),
  /// in the body frame at scan.t_end_s.
  PointCloud deskewedInBody(const io::Scan& scan, const Trajectory& sweep_T_odom_body) const;

  /// A deskewed scan's points for the local map: one per voxel of odometry.local_map_voxel_m,
  /// the odometry.local_map_point of it.
  std::vector<Eigen::Vector3d> localMapPoints(const PointCloud& cloud_in_body) const;

 private:
  /// The scan's returns within the range limits and outside the rig's boxes, in the lidar frame.
  PointCloud forestPointsInLidar(const io::Scan& scan) const;

  double min_range_m_, max_range_m_;
  double local_map_voxel_m_;
  preprocess::VoxelRepresentative local_map_point_;
  lie::SE3 T_body_lidar_;
  std::vector<OrientedBox> self_boxes_lidar_;  ///< rig.self_boxes_body in the lidar frame
  MovingBoxes moving_boxes_body_;
};

}  // namespace taiga::pipeline
