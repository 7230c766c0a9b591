#pragma once
// A robust circle fit to the horizontal cross-section of a stem (docs/trees.md, "Circle fit").
//
// Stem slices are not clean circles: branches, twigs and mixed edge returns lie off the stem, and a
// stem seen from one side gives a partial arc. So the fit is (1) RANSAC over three-point circles,
// scored by the points within a band of the circle, then (2) a geometric least-squares refinement
// of (cx, cy, r) minimising sum w_i (|p_i - c| - r)^2 with Tukey's biweight w_i (iteratively
// reweighted, the scale from the median absolute deviation of the residuals). A plain algebraic
// (Kasa) fit would be pulled by every off-stem point and is biased small on partial arcs.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>

namespace taiga::trees {

struct CircleFitOptions {
  double min_radius_m = 0.02;
  double max_radius_m = 0.8;
  /// A point is a RANSAC inlier within this distance of the circle, m (the map's noise plus the
  /// bark's roughness).
  double inlier_band_m = 0.025;
  int ransac_iterations = 1000;
  /// Where beams are known (fitCircleAlongBeams): a point's 1-sigma across its beam, m (the
  /// keyframe's placement, the beam's footprint, the bark).
  double across_beam_sigma_m = 0.01;
  std::uint64_t seed = 1;  ///< the RANSAC draws are deterministic for a given seed
};

struct CircleFit {
  Eigen::Vector2d center_m = Eigen::Vector2d::Zero();
  double radius_m = 0.0;
  double rms_m = 0.0;       ///< RMS of the inliers' |p - c| - r (across the surface)
  std::size_t inliers = 0;  ///< points with a non-zero final weight
  double arc_deg = 0.0;     ///< angular coverage of the inliers, in 10 deg sectors
  /// Share of the inliers in the densest 30 deg: near 1 for a ring drawn through one dense arc
  /// (a stem's visible side) and sparse clutter around it.
  double densest_share = 1.0;
  double sigma_radius_m = 0.0;  ///< 1-sigma of the radius from the weighted normal equations
  double sigma_center_m = 0.0;  ///< 1-sigma of the centre (the larger axis of its ellipse)
  bool along_beams = false;     ///< an inlier's residual was measured along its beam
};

/// The fit to `points_m` (x, y), or nothing when no circle within the radius range has at least
/// 5 inliers.
std::optional<CircleFit> fitCircleRobust(std::span<const Eigen::Vector2d> points_m,
                                         const CircleFitOptions& options = {});

/// The geometric refinement alone, from a starting circle (used when the centre is known roughly,
/// e.g. predicted from the slice below). Its residual is across the surface; where the sensors'
/// positions are known, fitStemSection measures along the beams (beam_circle_fit.hpp).
std::optional<CircleFit> refineCircle(std::span<const Eigen::Vector2d> points_m,
                                      const Eigen::Vector2d& center_m, double radius_m,
                                      const CircleFitOptions& options = {});

/// A stem section's circle from a starting circle: refineCircle across the surface, then, when
/// `beams` are given (each point's horizontal beam direction, unit, from the sensor towards the
/// point; a zero vector where unknown), fitCircleAlongBeams from the same start with the first
/// fit's RMS (within 1-5 cm) as the range noise, unless its inliers cover less than 0.6 of the
/// first fit's arc: then the fit across the surface. Across the surface, a lidar's range noise
/// (which lies along the beam) makes a one-sided arc's circle small, and at 13 m on dark bark it
/// fills a thin stem's visible side into a crescent whose circle is 2-4 cm too small in radius;
/// along the beams it does not. The arc check keeps a scattered section (views from keyframes that
/// do not quite meet) from escaping to a large circle through one view's arc (docs/trees.md,
/// "Where the DBH error comes from").
std::optional<CircleFit> fitStemSection(std::span<const Eigen::Vector2d> points_m,
                                        const Eigen::Vector2d& center_m, double radius_m,
                                        const CircleFitOptions& options = {},
                                        std::span<const Eigen::Vector2d> beams = {});

/// The 1-sigma of fitStemSection's radius from a delete-one-block jackknife over the directions
/// the points were seen from: sorted by their beam's azimuth (or, where unknown, by their azimuth
/// around `fit`'s centre) and cut into 8 blocks of equal count; the section is fitted again (from
/// the same start) without each block, sigma = sqrt((g-1)/g sum (r_k - mean r)^2) over the g
/// refits. It sees what the formal sigma (points independent) cannot: views from keyframes that
/// do not quite meet, which move whole arcs, and a section that is not round. 0 when there are
/// fewer than 16 points or 3 refits.
double viewJackknifeSigmaRadius(std::span<const Eigen::Vector2d> points_m,
                                std::span<const Eigen::Vector2d> beams, const CircleFit& fit,
                                const Eigen::Vector2d& start_center_m, double start_radius_m,
                                const CircleFitOptions& options = {});

}  // namespace taiga::trees
