#pragma once
// Boxes that enclose parts of the rig whose returns are not forest: the operator, a harvester's
// cabin (fixed on the body) and its boom (moving, one set of boxes per scan, as the thesis
// extracted them; on a real machine they would come from the joint encoders).

#include <Eigen/Core>
#include <map>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace taiga {

/// An axis-aligned box in the frame it is given in.
struct Box {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min_m.array()).all() && (p.array() <= max_m.array()).all();
  }
};

/// A box with its own axes: the points p with |R_frame_box^T (p - center)| <= half_extent on
/// every axis.
struct OrientedBox {
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_extent_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_frame_box = Eigen::Matrix3d::Identity();

  static OrientedBox fromBox(const Box& box) {
    return {0.5 * (box.min_m + box.max_m), 0.5 * (box.max_m - box.min_m),
            Eigen::Matrix3d::Identity()};
  }
  bool contains(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d p_box = R_frame_box.transpose() * (p - center_m);
    return (p_box.cwiseAbs().array() <= half_extent_m.array()).all();
  }
  /// The same box expressed in another frame: T_new_frame maps this box's frame into it.
  OrientedBox expressedIn(const lie::SE3& T_new_frame) const {
    return {T_new_frame * center_m, half_extent_m,
            T_new_frame.rotation().matrix() * R_frame_box};
  }
};

/// Boxes that change from scan to scan, in the body frame, each set stamped with the start time
/// of its scan (the header stamp of the Ouster driver's clouds).
class MovingBoxes {
 public:
  void add(double stamp_s, const OrientedBox& box_body) { by_stamp_[stamp_s].push_back(box_body); }
  bool empty() const { return by_stamp_.empty(); }
  std::size_t stamps() const { return by_stamp_.size(); }
  /// The set of the scan spanning [t_start_s, t_end_s]: the one stamped nearest after
  /// t_start_s - 1 ms and before t_end_s (the first firing may have no return, so the scan's
  /// first point can come a little after its stamp). None if there is no such set.
  std::vector<OrientedBox> forScan(double t_start_s, double t_end_s) const {
    constexpr double kTolerance_s = 1e-3;
    const auto it = by_stamp_.lower_bound(t_start_s - kTolerance_s);
    if (it == by_stamp_.end() || !(it->first < t_end_s)) return {};
    return it->second;
  }

 private:
  std::map<double, std::vector<OrientedBox>> by_stamp_;
};

}  // namespace taiga
