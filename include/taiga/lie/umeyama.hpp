#pragma once
// Least-squares alignment of two paired point sets (Umeyama, "Least-squares estimation of
// transformation parameters between two point patterns", IEEE PAMI 1991), shared by the
// evaluation (evo's se3/sim3 alignment, eval/alignment.hpp) and georeferencing (the closed rigid
// fit): the cross-covariance of the centred points, its SVD U D V^T, R = U S V^T with
// S = diag(1, 1, det(U) det(V)) (a rotation, never a reflection), scale c = trace(D S) / sigma^2
// (sigma^2 the source's mean squared distance from its centroid) and t = mean_target -
// c R mean_source. Eigen::umeyama computes it; this header adds the rank test and the lie types.

#include <span>

#include "taiga/lie/se3.hpp"

namespace taiga::lie {

/// p_target = scale * (R * p_source) + t, with R and t in T_target_source.
struct Similarity {
  SE3 T_target_source;
  double scale = 1.0;
};

/// The number of singular values of the centred points' cross-covariance above machine epsilon
/// (evo's test). Below 2 (all points on a line, or on one point) the rotation about that line is
/// not determined and umeyama() returns an arbitrary one. 0 for empty sets.
int crossCovarianceRank(std::span<const Vector3> source, std::span<const Vector3> target);

/// Kabsch's step: the rotation R maximising trace(R^T M), i.e. of the least-squares problems whose
/// cost is -2 trace(R^T M) plus constants. M = U S V^T, R = U diag(1, 1, det(U V^T)) V^T (a
/// rotation, never a reflection).
Matrix3 kabschRotation(const Matrix3& M);

/// The least-squares similarity (with_scale) or rigid transform (scale 1) taking source[i] onto
/// target[i]; the sets have the same size and are not empty.
Similarity umeyama(std::span<const Vector3> source, std::span<const Vector3> target,
                   bool with_scale);

}  // namespace taiga::lie
