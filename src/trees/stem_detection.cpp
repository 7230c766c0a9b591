#include "taiga/trees/stem_detection.hpp"

#include <tbb/parallel_for.h>
#include <tsl/robin_map.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "taiga/core/hash.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/trees/circle_fit.hpp"

namespace taiga::trees {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

std::int64_t cellKey(std::int64_t ix, std::int64_t iy) { return (ix << 32) ^ (iy & 0xffffffff); }

template <typename T>
using CellMap = tsl::robin_map<std::int64_t, T, MixedKeyHash>;

// Points as (x, y, height above ground), bucketed by square columns for disc queries, with the
// (x, y) of the sensor that saw each one when known.
class ColumnIndex {
 public:
  ColumnIndex(std::vector<Vector3d> points_xyh, std::vector<Vector2d> viewpoints_xy, double cell_m)
      : points_(std::move(points_xyh)), viewpoints_(std::move(viewpoints_xy)), cell_m_(cell_m) {
    std::vector<std::pair<std::int64_t, std::uint32_t>> keyed(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i)
      keyed[i] = {keyOf(points_[i].head<2>()), static_cast<std::uint32_t>(i)};
    std::sort(keyed.begin(), keyed.end());
    order_.resize(keyed.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) {
      order_[i] = keyed[i].second;
      auto [it, inserted] = ranges_.try_emplace(keyed[i].first, i, i + 1);
      if (!inserted) it.value().second = i + 1;
    }
  }

  const std::vector<Vector3d>& points() const { return points_; }

  /// The horizontal direction from the sensor to point i (unit); zero when unknown (no or a NaN
  /// viewpoint) or the point lies within 10 cm of it.
  Vector2d beamOf(std::uint32_t i) const {
    if (viewpoints_.empty()) return Vector2d::Zero();
    const Vector2d beam = points_[i].head<2>() - viewpoints_[i];
    const double length_m = beam.norm();
    return length_m > 0.1 ? Vector2d(beam / length_m) : Vector2d::Zero();
  }

  /// The horizontal distance from the sensor to point i; NaN when unknown.
  double rangeOf(std::uint32_t i) const {
    if (viewpoints_.empty()) return std::numeric_limits<double>::quiet_NaN();
    return (points_[i].head<2>() - viewpoints_[i]).norm();
  }

  /// Calls f(point, i) for the points within `radius_m` of `center_m` with h_lo <= h < h_hi.
  template <typename F>
  void forEachNear(const Vector2d& center_m, double radius_m, double h_lo, double h_hi,
                   F&& f) const {
    const auto lo = cellOf(center_m - Vector2d::Constant(radius_m));
    const auto hi = cellOf(center_m + Vector2d::Constant(radius_m));
    for (std::int64_t iy = lo.second; iy <= hi.second; ++iy)
      for (std::int64_t ix = lo.first; ix <= hi.first; ++ix) {
        const auto range = ranges_.find(cellKey(ix, iy));
        if (range == ranges_.end()) continue;
        for (std::size_t k = range->second.first; k < range->second.second; ++k) {
          const Vector3d& p = points_[order_[k]];
          if (p.z() >= h_lo && p.z() < h_hi && (p.head<2>() - center_m).norm() <= radius_m)
            f(p, order_[k]);
        }
      }
  }

 private:
  std::pair<std::int64_t, std::int64_t> cellOf(const Vector2d& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell_m_)),
            static_cast<std::int64_t>(std::floor(p.y() / cell_m_))};
  }
  std::int64_t keyOf(const Vector2d& p) const {
    const auto [ix, iy] = cellOf(p);
    return cellKey(ix, iy);
  }
  std::vector<Vector3d> points_;
  std::vector<Vector2d> viewpoints_;  ///< empty, or one per point
  double cell_m_;
  std::vector<std::uint32_t> order_;
  CellMap<std::pair<std::size_t, std::size_t>> ranges_;
};

// Connected groups of the points' 5 cm pixels (8-neighbourhood): candidate stem cross-sections.
std::vector<std::vector<Vector2d>> pixelClusters(const std::vector<Vector2d>& points_m) {
  constexpr double kPixel_m = 0.05;
  auto pixelOf = [](const Vector2d& p) {
    return std::pair<std::int64_t, std::int64_t>{
        static_cast<std::int64_t>(std::floor(p.x() / kPixel_m)),
        static_cast<std::int64_t>(std::floor(p.y() / kPixel_m))};
  };
  CellMap<std::int32_t> label;  // -1: occupied, not yet labelled
  for (const Vector2d& p : points_m) {
    const auto [ix, iy] = pixelOf(p);
    label.emplace(cellKey(ix, iy), -1);
  }
  // Labels in a deterministic order: the pixels sorted by key.
  std::vector<std::int64_t> keys;
  keys.reserve(label.size());
  for (const auto& [key, value] : label) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  std::int32_t labels = 0;
  std::vector<std::int64_t> stack;
  for (const std::int64_t seed : keys) {
    if (label[seed] >= 0) continue;
    label[seed] = labels;
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::int64_t key = stack.back();
      stack.pop_back();
      const std::int64_t ix = key >> 32;
      const auto iy = static_cast<std::int64_t>(static_cast<std::int32_t>(key & 0xffffffff));
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const auto it = label.find(cellKey(ix + dx, iy + dy));
          if (it == label.end() || it->second >= 0) continue;
          it.value() = labels;
          stack.push_back(it->first);
        }
    }
    ++labels;
  }
  std::vector<std::vector<Vector2d>> clusters(static_cast<std::size_t>(labels));
  for (const Vector2d& p : points_m) {
    const auto [ix, iy] = pixelOf(p);
    clusters[static_cast<std::size_t>(label.at(cellKey(ix, iy)))].push_back(p);
  }
  return clusters;
}

struct Slice {
  double h_m;
  Vector2d center_m;
  double radius_m;
};

// The next slice's circle, started from the neighbouring slice's; nothing when it does not agree.
std::optional<Slice> trackSlice(const ColumnIndex& index, const Slice& from, double h_lo,
                                double h_hi, const StemOptions& o, const CircleFitOptions& fit) {
  const double gap_m = std::abs(0.5 * (h_lo + h_hi) - from.h_m);
  const double max_shift_m = 0.04 + gap_m * std::tan(o.max_lean_deg / kDegPerRad);
  std::vector<Vector2d> near;
  index.forEachNear(from.center_m, from.radius_m + max_shift_m + 0.1, h_lo, h_hi,
                    [&](const Vector3d& p, std::uint32_t) { near.push_back(p.head<2>()); });
  const std::optional<CircleFit> c = refineCircle(near, from.center_m, from.radius_m, fit);
  if (!c || c->inliers < 6 || c->arc_deg < 40.0) return std::nullopt;
  if ((c->center_m - from.center_m).norm() > max_shift_m) return std::nullopt;
  if (std::abs(c->radius_m - from.radius_m) > 0.25 * from.radius_m + 0.02) return std::nullopt;
  return Slice{0.5 * (h_lo + h_hi), c->center_m, c->radius_m};
}

// Slices up and down from the seed until two in a row fail (the crown, or the ground's clutter).
std::vector<Slice> trackStem(const ColumnIndex& index, const Slice& seed, const StemOptions& o,
                             const CircleFitOptions& fit) {
  std::vector<Slice> slices{seed};
  for (int direction : {+1, -1}) {
    Slice from = seed;
    int misses = 0;
    for (double h = seed.h_m + direction * o.slice_m;
         h > o.lowest_slice_m && h < o.highest_slice_m && misses < 2; h += direction * o.slice_m) {
      const std::optional<Slice> next =
          trackSlice(index, from, h - 0.5 * o.slice_m, h + 0.5 * o.slice_m, o, fit);
      if (!next) {
        ++misses;
        continue;
      }
      misses = 0;
      slices.push_back(*next);
      from = *next;
    }
  }
  return slices;
}

// x(h) = a + b (h - h_bh), y likewise, by least squares over the slice centres.
struct Axis {
  Vector2d at_breast_height;
  Vector2d slope;
  double rms_m;
};
Axis fitAxis(const std::vector<Slice>& slices, double breast_height_m) {
  Eigen::Matrix2d AtA = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d AtB = Eigen::Matrix2d::Zero();  // columns: x, y
  for (const Slice& s : slices) {
    const Eigen::Vector2d a(1.0, s.h_m - breast_height_m);
    AtA += a * a.transpose();
    AtB += a * s.center_m.transpose();
  }
  const Eigen::Matrix2d solution = AtA.ldlt().solve(AtB);
  Axis axis{solution.row(0).transpose(), solution.row(1).transpose(), 0.0};
  double sq = 0.0;
  for (const Slice& s : slices)
    sq +=
        (s.center_m - axis.at_breast_height - axis.slope * (s.h_m - breast_height_m)).squaredNorm();
  axis.rms_m = std::sqrt(sq / static_cast<double>(slices.size()));
  return axis;
}

// dr/dh by least squares over the slices from `from_h_m` up (above the butt's swell), kept within
// [-3 cm, 0] per metre: stems narrow upwards, and a slice series that widens is a branch whorl or
// clutter, not taper to extrapolate. Zero with fewer than three slices.
double fitTaper(const std::vector<Slice>& slices, double from_h_m) {
  double n = 0.0, sh = 0.0, sr = 0.0, shh = 0.0, shr = 0.0;
  for (const Slice& s : slices) {
    if (s.h_m < from_h_m) continue;
    n += 1.0, sh += s.h_m, sr += s.radius_m, shh += s.h_m * s.h_m, shr += s.h_m * s.radius_m;
  }
  const double det = n * shh - sh * sh;
  if (n < 3.0 || !(det > 1e-9)) return 0.0;
  return std::clamp((n * shr - sh * sr) / det, -0.03, 0.0);
}

double treeHeight(const CellMap<double>& canopy, double pixel_m, const Stem& stem,
                  double breast_height_m) {
  constexpr double kRadius_m = 0.75;
  const double reach_m = kRadius_m + stem.axis_slope.norm() * 40.0;
  const Vector2d c = stem.position_m.head<2>();
  double top_m = 0.0;
  const auto lo = ((c.array() - reach_m) / pixel_m).floor().cast<std::int64_t>();
  const auto hi = ((c.array() + reach_m) / pixel_m).floor().cast<std::int64_t>();
  for (std::int64_t iy = lo.y(); iy <= hi.y(); ++iy)
    for (std::int64_t ix = lo.x(); ix <= hi.x(); ++ix) {
      const auto it = canopy.find(cellKey(ix, iy));
      if (it == canopy.end() || it->second <= top_m) continue;
      const Vector2d pixel((ix + 0.5) * pixel_m, (iy + 0.5) * pixel_m);
      if ((pixel - stem.axisAt(it->second, breast_height_m)).norm() <= kRadius_m)
        top_m = it->second;
    }
  return top_m;
}

// A stem is solid: its cross-section has no points inside (a bush, a crown or a tangle of
// branches that happens to fit a ring does). Allowed inside: noise, and stray returns (a real
// TLS spruce has 5-8 % of its ring count there: branch stubs, scans slightly misaligned).
bool hollow(const std::vector<Vector2d>& points_m, const CircleFit& fit) {
  const double core_m = fit.radius_m - std::max(0.03, 3.0 * fit.rms_m);
  if (core_m <= 0.0) return true;
  const auto inside = std::count_if(points_m.begin(), points_m.end(), [&](const Vector2d& p) {
    return (p - fit.center_m).norm() < core_m;
  });
  return static_cast<double>(inside) <= 0.15 * static_cast<double>(fit.inliers) + 2.0;
}

// The points of a stem section moved to breast height: by the axis' lean, and radially by the
// taper (-taper (h - bh)); with their beams and horizontal ranges where the sensor is known.
struct Section {
  std::vector<Vector2d> upright_m, beams;
  std::vector<double> ranges_m;
};
Section sectionPoints(const ColumnIndex& index, const Axis& axis, double taper, double radius_m,
                      double h_lo, double h_hi, double bh) {
  Section section;
  const double reach_m = std::max(bh - h_lo, h_hi - bh) * axis.slope.norm();
  index.forEachNear(axis.at_breast_height, radius_m + 0.15 + reach_m, h_lo, h_hi,
                    [&](const Vector3d& p, std::uint32_t i) {
                      const Vector2d q = p.head<2>() - axis.slope * (p.z() - bh);
                      const Vector2d out = q - axis.at_breast_height;
                      const double norm = out.norm();
                      section.upright_m.push_back(
                          norm > 1e-9 ? Vector2d(q - out / norm * taper * (p.z() - bh)) : q);
                      section.beams.push_back(index.beamOf(i));
                      if (const double range_m = index.rangeOf(i); std::isfinite(range_m))
                        section.ranges_m.push_back(range_m);
                    });
  return section;
}

// Steps 2-5 of the header for one seed circle: the slices along the stem, the axis, the DBH fit
// and the checks that it is a stem; nothing when it is not.
std::optional<Stem> measureStem(const ColumnIndex& index, const TerrainModel& terrain,
                                const CircleFit& seed, const StemOptions& o,
                                const CircleFitOptions& fit) {
  const double bh = o.breast_height_m;
  const std::vector<Slice> slices = trackStem(index, {bh, seed.center_m, seed.radius_m}, o, fit);
  if (slices.size() < o.min_slices) return std::nullopt;
  const Axis axis = fitAxis(slices, bh);
  const double lean_rad = std::atan(axis.slope.norm());
  if (lean_rad * kDegPerRad > o.max_lean_deg) return std::nullopt;

  // DBH: the points of the band around breast height, moved there by the axis' lean and the
  // slices' taper, fitted around the axis; along each point's beam where the sensor's position is
  // known (fitStemSection). A band with few points (a far stem: its radius at 1.0-1.6 m alone is
  // weakly determined) is widened in steps towards the section StemOptions::dbh_section_*, within
  // the slices the stem was tracked through (BENCHMARK.md, "Session 61").
  const auto [lowest, highest] = std::minmax_element(
      slices.begin(), slices.end(), [](const Slice& a, const Slice& b) { return a.h_m < b.h_m; });
  const double band_lo = bh - o.dbh_band_half_m, band_hi = bh + o.dbh_band_half_m;
  const double tracked_lo = std::min(band_lo, lowest->h_m - 0.5 * o.slice_m);
  const double tracked_hi = std::max(band_hi, highest->h_m + 0.5 * o.slice_m);
  const double taper = fitTaper(slices, band_lo);
  Section section;
  for (const double share : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double lo = band_lo - share * (o.dbh_section_below_m - o.dbh_band_half_m);
    const double hi = band_hi + share * (o.dbh_section_above_m - o.dbh_band_half_m);
    section = sectionPoints(index, axis, taper, seed.radius_m, std::max(lo, tracked_lo),
                            std::min(hi, tracked_hi), bh);
    if (section.upright_m.size() >= o.dbh_band_enough_points) break;
  }
  const std::vector<Vector2d>& upright = section.upright_m;
  const std::vector<Vector2d>& beams = section.beams;
  const double max_rms_m =
      slices.size() >= o.long_stem_slices ? o.max_fit_rms_m : 2.0 / 3.0 * o.max_fit_rms_m;
  const auto isStem = [&](const std::optional<CircleFit>& f) {
    return f && f->arc_deg >= o.min_arc_deg && f->rms_m <= max_rms_m &&
           f->densest_share <= o.max_densest_share && hollow(upright, *f);
  };
  std::optional<CircleFit> dbh_fit =
      fitStemSection(upright, axis.at_breast_height, seed.radius_m, fit, beams);
  if (!isStem(dbh_fit)) return std::nullopt;
  // The formal sigma treats the band's points as independent; views that do not quite meet move
  // whole arcs, which the view jackknife sees (circle_fit.hpp).
  double sigma_radius_m = std::max(
      dbh_fit->sigma_radius_m, viewJackknifeSigmaRadius(upright, beams, *dbh_fit,
                                                        axis.at_breast_height, seed.radius_m, fit));
  // Along the beams a one-sided arc's radius can be left undetermined (a flat profile out to
  // large circles): when its sigma is over half of it, the fit across the surface, whose bias is
  // bounded, with its own jackknife (views blocked by azimuth around the centre). On the
  // harvester's strip road (one-sided views) the along-beam fit alone made 23 cm stems 39 cm
  // (BENCHMARK.md, "Session 58"); but on a far noisy crescent the fit across is 2-4 cm small in
  // DBH, so a fifth, as before session 61, gave that bias to a third of the far stems.
  if (dbh_fit->along_beams && sigma_radius_m > 0.5 * dbh_fit->radius_m) {
    dbh_fit = fitStemSection(upright, axis.at_breast_height, seed.radius_m, fit);
    if (!isStem(dbh_fit)) return std::nullopt;
    sigma_radius_m = std::max(
        dbh_fit->sigma_radius_m,
        viewJackknifeSigmaRadius(upright, {}, *dbh_fit, axis.at_breast_height, seed.radius_m, fit));
  }
  const double lean_scale = 2.0 / (1.0 + 1.0 / std::cos(lean_rad));
  Stem stem;
  stem.dbh_m = 2.0 * dbh_fit->radius_m * lean_scale;
  if (stem.dbh_m < o.min_dbh_m || stem.dbh_m > o.max_dbh_m) return std::nullopt;
  // The map's share, common to all views of the stem (StemOptions::dbh_sigma_per_range).
  const double map_sigma_m =
      section.ranges_m.empty() ? 0.0 : o.dbh_sigma_per_range * percentile(section.ranges_m, 50.0);
  stem.dbh_sigma_m = std::hypot(2.0 * sigma_radius_m * lean_scale, map_sigma_m);
  stem.ground_z_m = terrain.heightAt(dbh_fit->center_m.x(), dbh_fit->center_m.y());
  stem.position_m = Vector3d(dbh_fit->center_m.x(), dbh_fit->center_m.y(), stem.ground_z_m + bh);
  stem.axis_slope = axis.slope;
  stem.lean_deg = lean_rad * kDegPerRad;
  stem.lean_azimuth_deg =
      std::fmod(std::atan2(axis.slope.y(), axis.slope.x()) * kDegPerRad + 360.0, 360.0);
  stem.points = dbh_fit->inliers;
  stem.fit_rms_m = dbh_fit->rms_m;
  stem.arc_deg = dbh_fit->arc_deg;
  stem.dbh_along_beams = dbh_fit->along_beams;
  stem.slices = slices.size();
  for (const Slice& s : slices) stem.top_slice_m = std::max(stem.top_slice_m, s.h_m);
  stem.quality = stem.fit_rms_m > 0.02 || axis.rms_m > 0.03 ? StemQuality::kPoor
                 : stem.arc_deg < 180.0                     ? StemQuality::kPartial
                                                            : StemQuality::kGood;
  return stem;
}

}  // namespace

std::string qualityName(StemQuality quality) {
  switch (quality) {
    case StemQuality::kGood:
      return "good";
    case StemQuality::kPartial:
      return "partial";
    case StemQuality::kPoor:
      return "poor";
  }
  return "poor";
}

std::vector<Stem> detectStems(std::span<const Vector3d> points_m, const TerrainModel& terrain,
                              const StemOptions& o, const Viewpoints& viewpoints) {
  const std::span<const std::uint32_t> viewpoint_of = viewpoints.of_point;
  if (!viewpoint_of.empty() && viewpoint_of.size() != points_m.size())
    throw std::invalid_argument("detectStems: viewpoints must be empty or one per point");
  for (const std::uint32_t k : viewpoint_of)
    if (k != Viewpoints::kUnknown && k >= viewpoints.positions_m.size())
      throw std::invalid_argument("detectStems: a point's viewpoint index is out of range");
  const auto viewpointXy = [&](std::size_t i) -> Vector2d {
    const std::uint32_t k = viewpoint_of[i];
    return k == Viewpoints::kUnknown ? Vector2d::Constant(std::nan(""))
                                     : Vector2d(viewpoints.positions_m[k].head<2>());
  };
  const double bh = o.breast_height_m;
  const double band_lo = bh - o.dbh_band_half_m, band_hi = bh + o.dbh_band_half_m;
  std::vector<Vector3d> slab;
  std::vector<Vector2d> slab_viewpoints, band;
  constexpr double kCanopyPixel_m = 0.25;
  CellMap<double> canopy;  // the highest point per pixel, above the ground
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const Vector3d& p = points_m[i];
    if (!p.allFinite()) continue;
    const double h = p.z() - terrain.heightAt(p.x(), p.y());
    if (h >= o.lowest_slice_m && h < o.highest_slice_m) {
      slab.emplace_back(p.x(), p.y(), h);
      if (!viewpoint_of.empty()) slab_viewpoints.push_back(viewpointXy(i));
    }
    if (h >= band_lo && h < band_hi) band.push_back(p.head<2>());
    const auto key = cellKey(static_cast<std::int64_t>(std::floor(p.x() / kCanopyPixel_m)),
                             static_cast<std::int64_t>(std::floor(p.y() / kCanopyPixel_m)));
    auto [it, inserted] = canopy.try_emplace(key, h);
    if (!inserted && h > it->second) it.value() = h;
  }
  const ColumnIndex index(std::move(slab), std::move(slab_viewpoints), 0.25);
  const CircleFitOptions fit{.min_radius_m = 0.5 * o.min_dbh_m * 0.7,
                             .max_radius_m = 0.5 * o.max_dbh_m,
                             .inlier_band_m = o.inlier_band_m,
                             .across_beam_sigma_m = o.across_beam_sigma_m};

  // A cluster may hold several stems joined by branches: fit, take the circle's points out,
  // fit again.
  const auto measureCluster = [&](std::vector<Vector2d>& cluster, std::vector<Stem>& found) {
    if (o.stop.stop_requested()) return;
    for (int attempt = 0; attempt < 4 && cluster.size() >= 10; ++attempt) {
      const std::optional<CircleFit> seed = fitCircleRobust(cluster, fit);
      if (!seed) break;
      std::erase_if(cluster, [&](const Vector2d& p) {
        return (p - seed->center_m).norm() < seed->radius_m + 0.1;
      });
      if (std::optional<Stem> stem = measureStem(index, terrain, *seed, o, fit)) {
        stem->height_m = std::max(stem->top_slice_m, treeHeight(canopy, kCanopyPixel_m, *stem, bh));
        found.push_back(*stem);
      }
    }
  };
  std::vector<std::vector<Vector2d>> clusters = pixelClusters(band);
  std::vector<std::vector<Stem>> found(clusters.size());
  if (o.parallel) {
    tbb::parallel_for(std::size_t{0}, clusters.size(),
                      [&](std::size_t c) { measureCluster(clusters[c], found[c]); });
  } else {
    for (std::size_t c = 0; c < clusters.size(); ++c) measureCluster(clusters[c], found[c]);
  }
  std::vector<Stem> candidates;  // in the clusters' order, whichever thread measured them
  for (const std::vector<Stem>& stems : found)
    candidates.insert(candidates.end(), stems.begin(), stems.end());

  // One stem per place: of overlapping circles the one with the most points stays.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Stem& a, const Stem& b) { return a.points > b.points; });
  std::vector<Stem> stems;
  for (const Stem& c : candidates) {
    const bool overlaps = std::any_of(stems.begin(), stems.end(), [&](const Stem& s) {
      return (s.position_m.head<2>() - c.position_m.head<2>()).norm() < 0.5 * (s.dbh_m + c.dbh_m);
    });
    if (!overlaps) stems.push_back(c);
  }
  sortByPosition(stems);
  return stems;
}

void sortByPosition(std::vector<Stem>& stems) {
  std::sort(stems.begin(), stems.end(), [](const Stem& a, const Stem& b) {
    return a.position_m.x() != b.position_m.x() ? a.position_m.x() < b.position_m.x()
                                                : a.position_m.y() < b.position_m.y();
  });
}

std::vector<std::uint32_t> stemMembership(std::span<const Vector3d> points_m,
                                          const TerrainModel& terrain,
                                          std::span<const Stem> stems) {
  constexpr double kCell_m = 1.0;
  CellMap<std::vector<std::uint32_t>> near;  // stems by 1 m cell, +-1 cell
  for (std::size_t s = 0; s < stems.size(); ++s) {
    const auto ix = static_cast<std::int64_t>(std::floor(stems[s].position_m.x() / kCell_m));
    const auto iy = static_cast<std::int64_t>(std::floor(stems[s].position_m.y() / kCell_m));
    for (std::int64_t dy = -1; dy <= 1; ++dy)
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        near[cellKey(ix + dx, iy + dy)].push_back(static_cast<std::uint32_t>(s));
  }
  std::vector<std::uint32_t> member(points_m.size(), 0);
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const Vector3d& p = points_m[i];
    if (!p.allFinite()) continue;
    const auto it = near.find(cellKey(static_cast<std::int64_t>(std::floor(p.x() / kCell_m)),
                                      static_cast<std::int64_t>(std::floor(p.y() / kCell_m))));
    if (it == near.end()) continue;
    const double h = p.z() - terrain.heightAt(p.x(), p.y());
    for (const std::uint32_t s : it->second) {
      const Stem& stem = stems[s];
      if (h < -0.2 || h > stem.top_slice_m + 0.15) continue;
      const double radius_m = 0.5 * stem.dbh_m * (h < 1.0 ? 1.3 : 1.0);
      if ((p.head<2>() - stem.axisAt(h)).norm() < radius_m + 0.05) {
        member[i] = s + 1;
        break;
      }
    }
  }
  return member;
}

}  // namespace taiga::trees
