#pragma once
// Alignment of an estimated trajectory to a reference before comparing them, as evo:
//
//   se3    (evo -a):              Umeyama on the positions without scale; T_ref_est applied to
//                                 every estimated pose: P'_i = T_ref_est * P_i.
//   sim3   (evo -a -s, i.e. -as): Umeyama with scale s; positions are scaled first, then
//                                 transformed: p'_i = R (s p_i) + t, R'_i = R R_i.
//   origin (evo --align_origin):  T_ref_est = Q_0 * P_0^-1, so the first estimated pose lands on
//                                 the first reference pose (orientation included).
//   none:                         the estimate as it is.
//
// Umeyama, "Least-squares estimation of transformation parameters between two point patterns",
// IEEE PAMI 1991, as in evo's geometry.umeyama_alignment (lie/umeyama.hpp, which georef's closed
// fit uses too): the covariance of the centred positions, its SVD U D V^T, R = U S V^T with
// S = diag(1, 1, det(U) det(V)), scale c = trace(D S) / sigma_x^2 and t = mean_ref - c R mean_est.
// Alignment uses all associated pairs (evo's default, --n_to_align all).

#include <string>
#include <string_view>
#include <vector>

#include "taiga/core/trajectory.hpp"

namespace taiga::eval {

enum class Alignment { kSe3, kSim3, kOrigin, kNone };

/// "se3", "sim3", "origin", "none".
std::string_view alignmentName(Alignment alignment);
/// Inverse of alignmentName(); InputError naming the accepted values otherwise.
Alignment parseAlignment(std::string_view name);

/// The similarity p_ref = scale * R * p_est + t (scale 1 except for sim3).
struct AlignmentTransform {
  lie::SE3 T_ref_est;  ///< rotation and translation
  double scale = 1.0;
};

/// Umeyama's least-squares similarity taking `source` onto `target` (same size; lie::umeyama).
/// Throws InputError when there are no points or the covariance has rank < 2 (all points on one
/// line, or a single point): the rotation about that line is then not determined, and evo refuses
/// the same inputs.
AlignmentTransform umeyama(const std::vector<Eigen::Vector3d>& source,
                           const std::vector<Eigen::Vector3d>& target, bool with_scale);

/// The transform `alignment` chooses for est -> ref (pairs of equal size, not empty).
AlignmentTransform computeAlignment(const std::vector<StampedPose>& est,
                                    const std::vector<StampedPose>& ref, Alignment alignment);

/// The se3 alignment for what hangs on the trajectory (its map, its trees), which a rotation
/// error moves by its lever arm: Umeyama's cost on the positions plus lever_m^2 times the
/// orientations' chordal distance, sum_i |y_i - R x_i - t|^2 + lever_m^2 |R_ref_i - R R_est_i|_F^2.
/// Both terms are linear in R, so R is Kabsch's on M = sum_i (y_i - y_mean)(x_i - x_mean)^T +
/// lever_m^2 sum_i R_ref_i R_est_i^T (M = U S V^T, R = U diag(1, 1, det(U V^T)) V^T), and t =
/// y_mean - R x_mean. With lever_m small against the path's extent this is Umeyama's alignment
/// where the positions determine the rotation; where they do not (a short, straight path: the
/// rotation about it), the orientations do. Pairs of equal size, not empty.
AlignmentTransform alignWithOrientations(const std::vector<StampedPose>& est,
                                         const std::vector<StampedPose>& ref, double lever_m);

/// Applies `transform` to every pose: positions scaled, then the rigid transform on the left.
std::vector<StampedPose> applyAlignment(const std::vector<StampedPose>& poses,
                                        const AlignmentTransform& transform);

}  // namespace taiga::eval
