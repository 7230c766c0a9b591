#pragma once
// Place recognition from stem positions (docs/mapping.md, "Relocalization", issue 25 item 2).
// A stem's axis is the same from every side and a forest's stems are a pattern of points whose
// mutual distances do not depend on where it is seen from: two stems of a keyframe at distance d
// with their diameters can only be two stems of the map at the same distance with the same
// diameters. Each such pair of pairs fixes a horizontal rigid motion (x, y, yaw); the one that
// puts most of the keyframe's stems onto map stems is the place, wherever dead reckoning left the
// keyframe (a window search reaches +-4 m and 45 deg from it; a 10 s lidar-only gap ends 8-15 m
// and 60-80 deg off).

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::mapping {

/// A stem as a landmark: its axis at breast height and its diameter.
struct StemMark {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double dbh_m = 0.0;
};

/// The stems of one scan in its own frame (trees::takeInventory on the scan levelled by
/// R_level_body, the rotation part of its map pose: the map is z-up to within the rig's tilt),
/// poor fits left out.
std::vector<StemMark> scanStemMarks(const PointCloud& scan_in_body, const lie::SO3& R_level_body);
/// The stems of a cloud in a z-up frame, in that frame.
std::vector<StemMark> cloudStemMarks(std::span<const Eigen::Vector3d> points_m);

/// Marks closer than merge_m (the same stem seen from several keyframes) as one, their mean.
std::vector<StemMark> mergeStemMarks(std::span<const StemMark> marks, double merge_m = 0.4);

struct ConstellationMatch {
  lie::SE3 T_target_source;  ///< yaw about z and a translation (z from the stems' heights)
  std::size_t inliers = 0;   ///< source stems within inlier_m of a target stem of similar DBH
  double rms_m = 0.0;        ///< horizontal RMS distance of the inliers
};

struct ConstellationOptions {
  double distance_tolerance_m = 0.15;  ///< of a pair's distance
  double dbh_tolerance = 0.25;         ///< relative, and at least 3 cm
  double inlier_m = 0.35;
  std::size_t min_inliers = 4;
  double min_pair_m = 1.5;  ///< shorter pairs fix the yaw poorly
  double max_pair_m = 25.0;
  std::size_t max_matches = 4;  ///< distinct solutions returned, best first
};

/// The horizontal motions that put the most source stems on target stems, at least min_inliers,
/// distinct (1 m or 5 deg apart), best first (most inliers, then the smaller RMS). Deterministic.
std::vector<ConstellationMatch> matchConstellations(std::span<const StemMark> source,
                                                    std::span<const StemMark> target,
                                                    const ConstellationOptions& options = {});

}  // namespace taiga::mapping
