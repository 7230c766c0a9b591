#pragma once
// Where the lidar's beam-divergence ring can change a return, decided from the geometry of the
// curve (a cone segment of a stem, branch or twig) on the near side of an edge, without casting
// the ring (lidar.cpp, pass 2).
//
// The ring rays leave the centre ray's origin at an angle whose tangent is tan_ring, so at range
// t they are at most rho(t) = tan_ring * t off the centre ray. Between a line and a cone segment
// (axis a + s (b - a), s in [0, 1]) the closest approach is the classic line-segment one
// (Ericson, Real-Time Collision Detection, 5.1.9; the squared distance is convex in s, so
// clamping the unconstrained s gives the nearest point of the segment). Both tests are
// conservative: 20 % and 2 mm of slack on rho, the thinner end's radius where the ring must stay
// on the cone and the thicker one's where it must miss; free ends (the top of a stem, twig and
// branch tips) need an axial margin; rays within ~12 deg of the axis (looking along a branch)
// are never settled.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "taiga/sim/scene.hpp"

namespace taiga::sim::detail {

/// Closest approach of the line origin + t d (unit d) to the segment a + s (b - a).
struct LineSegmentApproach {
  double distance_m = 0.0;  ///< between the line and the axis point at s
  double s = 0.0;           ///< axis parameter, unclamped (outside [0, 1]: beyond an end)
  double t_m = 0.0;         ///< along the line
  double sin_angle = 0.0;   ///< sine of the angle between the line and the axis
  double length_m = 0.0;    ///< of the axis
};

inline LineSegmentApproach approach(const CurveSegment& seg, const Eigen::Vector3d& origin,
                                    const Eigen::Vector3d& d, bool clamp_to_segment) {
  const Eigen::Vector3d v = seg.b_world - seg.a_world, w0 = origin - seg.a_world;
  const double b = d.dot(v), c = v.squaredNorm(), dd = d.dot(w0), e = v.dot(w0);
  const double den = c - b * b;  // |d|^2 |v|^2 sin^2
  LineSegmentApproach out;
  out.length_m = std::sqrt(c);
  out.sin_angle = c > 0 ? std::sqrt(std::max(0.0, den) / c) : 0.0;
  if (out.sin_angle < 0.2) return out;  // nearly parallel: the callers settle nothing
  out.s = (e - b * dd) / den;
  if (clamp_to_segment) out.s = std::clamp(out.s, 0.0, 1.0);
  const Eigen::Vector3d on_axis = seg.a_world + out.s * v;
  out.t_m = d.dot(on_axis - origin);
  out.distance_m = (origin + out.t_m * d - on_axis).norm();
  return out;
}

/// Slack on the ring's offset at range t.
inline double ringOffset(double tan_ring, double t_m) { return 1.2 * tan_ring * t_m + 0.002; }

/// True if every ring ray of a centre ray (origin, d) that hit curve segment `index` at range
/// `range_m` hits the same cone too (so the ring would return the centre's surface).
inline bool ringStaysOnCurve(const Scene& scene, std::int32_t index, const Eigen::Vector3d& origin,
                             const Eigen::Vector3d& d, double range_m, double tan_ring) {
  const CurveSegment seg = scene.curveSegment(index);
  const LineSegmentApproach ap = approach(seg, origin, d, false);
  if (ap.sin_angle < 0.2 || ap.s < 0.0 || ap.s > 1.0) return false;
  const double r_min = std::min(seg.radius_a_m, seg.radius_b_m);
  const double r_max = std::max(seg.radius_a_m, seg.radius_b_m);
  const double rho = ringOffset(tan_ring, std::max(range_m, ap.t_m) + r_max);
  if (ap.distance_m + rho > r_min) return false;
  // A free end must be far enough along the axis that no ring ray slips past it.
  const double margin_m = (rho + r_max) / ap.sin_angle;
  if (!seg.continues_before && ap.s * ap.length_m < margin_m) return false;
  if (!seg.continues_after && (1.0 - ap.s) * ap.length_m < margin_m) return false;
  return true;
}

/// True if no ring ray of the centre ray (origin, d) can touch curve segment `index` or the
/// segments joined to it (the nearer surface that a neighbouring pixel's centre ray hit).
inline bool ringMissesCurve(const Scene& scene, std::int32_t index, const Eigen::Vector3d& origin,
                            const Eigen::Vector3d& d, double tan_ring) {
  const CurveSegment seg = scene.curveSegment(index);
  auto misses = [&](const CurveSegment& s) {
    const LineSegmentApproach ap = approach(s, origin, d, true);
    if (ap.sin_angle < 0.2) return false;
    const double r_max = std::max(s.radius_a_m, s.radius_b_m);
    // The segment, capped by spheres of its larger radius, holds the cone.
    return ap.distance_m - r_max > ringOffset(tan_ring, std::max(ap.t_m, 0.0) + r_max);
  };
  if (!misses(seg)) return false;
  if (seg.continues_before && !misses(scene.curveSegment(index - 1))) return false;
  if (seg.continues_after && !misses(scene.curveSegment(index + 1))) return false;
  return true;
}

}  // namespace taiga::sim::detail
