#pragma once
// The tree list against a reference one (`taiga eval --trees`, docs/trees.md "Evaluation"):
// detection rate (recall), commission (false stems), DBH, position and height errors, by DBH class
// and by distance from the path, and the thesis' overlapping-tree ratio.
//
// Stems are compared at breast height in the reference frame (the estimate moved by the
// trajectory's alignment). A detected stem and a reference tree match when their positions are
// within `match_m`; pairs are taken closest first, each tree at most once. The reference trees
// counted are those with DBH >= min_dbh_m within max_path_distance_m of the reference path; a
// detected stem there that matches no reference tree (of any DBH) is a commission error.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "taiga/eval/alignment.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga::eval {

struct TreeAccuracyOptions {
  double match_m = 0.5;
  double min_dbh_m = 0.10;
  double max_path_distance_m = 15.0;
};

struct TreeClass {
  std::string label;          ///< e.g. "DBH 10-20 cm" or "0-5 m from the path"
  std::size_t reference = 0;  ///< reference trees in the class
  std::size_t detected = 0;   ///< of them matched
};

/// One pair of a matched stem and its reference tree, in the reference frame.
struct TreeMatch {
  long est_id = 0, ref_id = 0;
  Eigen::Vector2d est_xy_m, ref_xy_m;
  double est_dbh_m = 0.0, ref_dbh_m = 0.0;
  double path_distance_m = 0.0;
};

struct TreeAccuracy {
  TreeAccuracyOptions options;
  std::size_t reference = 0;  ///< reference trees counted
  std::size_t detected = 0;   ///< of them matched
  std::size_t estimated = 0;  ///< detected stems in the area
  std::size_t false_stems = 0;
  double recall = 0.0, commission = 0.0;
  double dbh_rmse_m = 0.0, dbh_bias_m = 0.0;  ///< over the matched counted trees, est - ref
  /// Share of the matched trees that state a DBH 1-sigma whose error is within 2 of it (an honest
  /// sigma: about 0.95); NaN when no estimated tree states one.
  double dbh_within_2_sigma = 0.0;
  double position_rmse_m = 0.0;                     ///< horizontal
  double height_rmse_m = 0.0, height_bias_m = 0.0;  ///< NaN when either file has no heights
  /// Reference trees whose breast-height circle overlaps a detected stem's (the thesis' measure).
  double overlap_ratio = 0.0;
  std::vector<TreeClass> by_dbh, by_distance;
  std::vector<TreeMatch> matches;
  std::vector<Eigen::Vector2d> missed_xy_m, false_xy_m;  ///< for the tree map plot
  std::vector<long> missed_ids, false_ids;
};

/// `estimate` is moved into the reference frame with `T` (est -> ref); `reference_path_m` is the
/// reference trajectory's positions (for the distance from the path).
TreeAccuracy evaluateTrees(const std::vector<trees::TreeRecord>& estimate,
                           const std::vector<trees::TreeRecord>& reference,
                           const AlignmentTransform& T,
                           const std::vector<Eigen::Vector3d>& reference_path_m,
                           const TreeAccuracyOptions& options = {});

}  // namespace taiga::eval
