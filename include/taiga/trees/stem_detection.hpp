#pragma once
// Stems, their diameter at breast height (DBH), position, lean and height, from a point cloud and
// its terrain (docs/trees.md, "Stems").
//
// 1. Seeds: the points 1.0-1.6 m above the ground, rasterised at 5 cm and grouped into connected
//    clusters; each cluster gets a robust circle fit (circle_fit.hpp).
// 2. Along the stem: 0.3 m slices from 0.4 m up to 4 m (or the crown), each fitted with the
//    circle of the slice next to it as the start, kept when its centre and radius agree with it.
//    A stem needs at least five consistent slices: bushes, boulders, logs and branches do not
//    give a vertical chain of circles. A stem is also solid: a ring with points inside it (a
//    crown, a bush) is not one.
// 3. The axis: a line through the slice centres (least squares in x(h), y(h)): the lean and the
//    position at breast height.
// 4. DBH: one robust circle fit to the points 1.0-1.6 m above the ground with the axis' lean
//    removed (each point moved by the axis' offset between its height and 1.3 m), so a thick band
//    gives many points while the taper above and the butt swell below average out. A horizontal
//    cut of a stem leaning by a is an ellipse with semi-axes r and r / cos(a): the fitted radius is
//    scaled by 2 / (1 + 1 / cos a) back to the stem's own.
// 5. Height: the highest point within 0.75 m of the axis carried up with its lean.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stop_token>
#include <string>
#include <vector>

#include "taiga/trees/terrain_model.hpp"

namespace taiga::trees {

struct StemOptions {
  double breast_height_m = 1.3;
  /// Stems are sought in the points breast_height +- this, and their DBH fitted to that band's
  /// points, each moved to breast height by the stem's lean and taper. A band with fewer than
  /// dbh_band_enough_points points is widened in steps up to the section from breast_height -
  /// dbh_section_below_m to + dbh_section_above_m (within the slices the stem was tracked through):
  /// a far stem has few points per metre.
  double dbh_band_half_m = 0.3;
  std::size_t dbh_band_enough_points = 400;
  double dbh_section_below_m = 0.5;
  double dbh_section_above_m = 1.5;
  /// Added in quadrature to the DBH 1-sigma of a stem whose points' sensors are known, times the
  /// median horizontal range they were seen from: the map's placement error common to all views
  /// of a stem, which no resampling of its views can see (a run's scans are 0.05-0.1 % too large
  /// for their trajectory, issue 25; the DBH bias grows by about 1 mm per metre of range:
  /// BENCHMARK.md, "Session 61").
  double dbh_sigma_per_range = 0.001;
  double min_dbh_m = 0.07;       ///< thinner stems are not reported (saplings, shrubs)
  double max_dbh_m = 1.2;
  double slice_m = 0.3;
  double lowest_slice_m = 0.4;   ///< the butt below is often hidden by vegetation and swells
  double highest_slice_m = 4.0;  ///< slices are tracked up to here or to the crown
  std::size_t min_slices =
      5;  ///< consistent slices a stem needs, the DBH band included (1.5 m of stem)
  double max_lean_deg = 25.0;
  double inlier_band_m = 0.025;  ///< see CircleFitOptions
  double across_beam_sigma_m = 0.01;  ///< see CircleFitOptions
  double min_arc_deg = 60.0;     ///< a DBH fit on less of the circle is not reported
  /// Nor one whose inliers scatter more (foliage, clutter that happens to make a ring); a stem
  /// tracked through fewer than long_stem_slices slices must scatter less than 2/3 of it: on noisy
  /// maps true stems scatter up to 3-4 cm but are long, while false rings were at most 8 slices.
  double max_fit_rms_m = 0.045;
  std::size_t long_stem_slices = 9;
  /// Nor a ring whose inliers crowd into 30 deg of it: a large ring through one stem's visible
  /// arc and the clutter around it, whose radius means nothing.
  double max_densest_share = 0.6;
  /// Measure the band's clusters on TBB's threads (the same stems as one thread: each cluster's
  /// fits are its own). Off by default: the run's tree worker has idle priority, and its fits must
  /// not run on the threads the odometry waits for.
  bool parallel = false;
  /// Once a stop is requested, the clusters not yet measured are skipped: the stems returned are
  /// then a part of the cloud's, for a caller that no longer wants them (the online tree map's
  /// update when the run ends, whose region the final inventory covers anyway).
  std::stop_token stop;
};

enum class StemQuality : std::uint8_t {
  kGood,     ///< arc >= 180 deg, consistent axis, fit RMS <= 2 cm
  kPartial,  ///< seen from one side (arc < 180 deg): the DBH is less certain
  kPoor,     ///< large fit RMS or few slices: check it
};
std::string qualityName(StemQuality quality);

struct Stem {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< axis at breast height (x, y, z)
  double ground_z_m = 0.0;                               ///< terrain height under the stem
  double dbh_m = 0.0;
  double dbh_sigma_m = 0.0;  ///< 1-sigma of the DBH from the fit
  double height_m = 0.0;     ///< highest point near the axis above the ground
  double lean_deg = 0.0;
  double lean_azimuth_deg = 0.0;  ///< direction of the lean, from +x towards +y
  Eigen::Vector2d axis_slope = Eigen::Vector2d::Zero();  ///< d(x, y)/dh of the axis
  std::size_t points = 0;                                ///< inliers of the DBH fit
  double fit_rms_m = 0.0;
  double arc_deg = 0.0;
  std::size_t slices = 0;        ///< consistent slices along the stem
  bool dbh_along_beams = false;  ///< the DBH fit's residuals were along the beams
  double top_slice_m = 0.0;      ///< height of the highest consistent slice above the ground
  StemQuality quality = StemQuality::kGood;

  /// The axis at height h above the ground (x, y).
  Eigen::Vector2d axisAt(double h_m, double breast_height_m = 1.3) const {
    return position_m.head<2>() + axis_slope * (h_m - breast_height_m);
  }
};

/// Where the points of a lidar map were measured from: the sensor's positions (a map's: one per
/// keyframe) and per point the index of its own, kUnknown where it is not known. 4 bytes per
/// point, where a position per point would take 24.
struct Viewpoints {
  static constexpr std::uint32_t kUnknown = 0xffffffff;
  std::span<const Eigen::Vector3d> positions_m;
  std::span<const std::uint32_t> of_point;  ///< empty (none known), or one per point
};

/// Stems in `points_m` (local coordinates, m) over `terrain`, sorted by x then y. Deterministic.
/// With `viewpoints` the DBH fit measures range noise along the beams (circle_fit.hpp).
/// std::invalid_argument when `viewpoints` does not fit the points.
std::vector<Stem> detectStems(std::span<const Eigen::Vector3d> points_m,
                              const TerrainModel& terrain, const StemOptions& options = {},
                              const Viewpoints& viewpoints = {});

/// Sorts by x, then y (the order of trees.csv).
void sortByPosition(std::vector<Stem>& stems);

/// Per point: 0 when it is on no stem, else 1 + the index of the stem whose surface it lies on
/// (within 5 cm of the fitted cylinder, from the ground up to the highest consistent slice).
std::vector<std::uint32_t> stemMembership(std::span<const Eigen::Vector3d> points_m,
                                          const TerrainModel& terrain, std::span<const Stem> stems);

}  // namespace taiga::trees
