#pragma once
// Whether a ring ray of the lidar's beam-divergence model can return something other than its
// centre ray, decided from the geometry of the curve (a cone segment of a stem, branch or twig)
// on the near side of an edge, without casting it (lidar.cpp, pass 2): a ring ray that certainly
// stays on the cone its centre ray hit, or certainly misses the nearer curve a neighbouring
// pixel's centre ray hit, sees what the centre ray saw.
//
// Between a line and a cone segment (axis a + s (b - a), s in [0, 1]) the closest approach is
// the classic line-segment one (Ericson, Real-Time Collision Detection, 5.1.9; the squared
// distance is convex in s, so clamping the unconstrained s gives the nearest point of the
// segment). Both tests are conservative: 2 mm + 0.01 % of the range of slack, the thinner end's
// radius where the ray must stay on the cone and the thicker one's where it must miss; free ends
// (the top of a stem, twig and branch tips) need an axial margin; rays within ~12 deg of the axis
// (looking along a branch) are never settled.

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

/// Slack for the float geometry Embree intersects (a few 1e-5 relative) and the taper, m.
inline double raySlack(double t_m) { return 0.002 + 1e-4 * std::abs(t_m); }

/// True if the ray (origin, unit d) certainly hits the cone of curve segment `index` (or a
/// segment joined to it): it passes the axis closer than the thinner end's radius, between the
/// ends, and a free end is not within reach of where it enters.
inline bool rayStaysOnCurve(const Scene& scene, std::int32_t index, const Eigen::Vector3d& origin,
                            const Eigen::Vector3d& d) {
  const CurveSegment seg = scene.curveSegment(index);
  const LineSegmentApproach ap = approach(seg, origin, d, false);
  if (ap.sin_angle < 0.2 || ap.s < 0.0 || ap.s > 1.0) return false;
  const double r_min = std::min(seg.radius_a_m, seg.radius_b_m);
  const double r_max = std::max(seg.radius_a_m, seg.radius_b_m);
  const double slack = raySlack(ap.t_m);
  if (ap.distance_m + slack > r_min) return false;
  // The ray crosses the mantle within r / tan(angle) of its closest approach along the axis.
  const double margin_m = r_max / ap.sin_angle + slack;
  if (!seg.continues_before && ap.s * ap.length_m < margin_m) return false;
  if (!seg.continues_after && (1.0 - ap.s) * ap.length_m < margin_m) return false;
  return true;
}

/// True if the ray (origin, unit d) certainly misses curve segment `index` and the segments
/// joined to it: it passes each further from its axis than the thicker end's radius (the
/// segment capped by spheres of that radius holds the cone).
inline bool rayMissesCurve(const Scene& scene, std::int32_t index, const Eigen::Vector3d& origin,
                           const Eigen::Vector3d& d) {
  const CurveSegment seg = scene.curveSegment(index);
  auto misses = [&](const CurveSegment& s) {
    const LineSegmentApproach ap = approach(s, origin, d, true);
    if (ap.sin_angle < 0.2) return false;
    const double r_max = std::max(s.radius_a_m, s.radius_b_m);
    return ap.distance_m - r_max > raySlack(ap.t_m);
  };
  if (!misses(seg)) return false;
  if (seg.continues_before && !misses(scene.curveSegment(index - 1))) return false;
  if (seg.continues_after && !misses(scene.curveSegment(index + 1))) return false;
  return true;
}

}  // namespace taiga::sim::detail
