// Procedural forest: stems, branches, foliage, saplings, shrubs, boulders and fallen logs.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <unordered_map>

#include "geometry_buffers.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim::detail {
namespace {

constexpr double kPi = std::numbers::pi;
/// Branches below this height above the ground are kept away from the walked path, m.
constexpr double kHeadZone_m = 4.0;

using Eigen::Vector2d;
using Eigen::Vector3d;
using Eigen::Vector4d;

/// Nearest-distance queries to the walked path (a polyline of closely spaced points).
class PathIndex {
 public:
  explicit PathIndex(const std::vector<Vector2d>& points) : points_(points) {
    for (std::size_t i = 0; i < points_.size(); ++i) cells_[key(points_[i])].push_back(i);
  }
  /// Distance to the nearest path point, capped at kCell_m * 2.
  double distance(const Vector2d& p) const {
    double best = 2.0 * kCell_m;
    const auto [cx, cy] = cell(p);
    for (long dx = -2; dx <= 2; ++dx) {
      for (long dy = -2; dy <= 2; ++dy) {
        const auto it = cells_.find(pack(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const std::size_t i : it->second) best = std::min(best, (points_[i] - p).norm());
      }
    }
    return best;
  }

 private:
  static constexpr double kCell_m = 4.0;
  static std::pair<long, long> cell(const Vector2d& p) {
    return {static_cast<long>(std::floor(p.x() / kCell_m)),
            static_cast<long>(std::floor(p.y() / kCell_m))};
  }
  static std::uint64_t pack(long x, long y) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(x)) << 32) |
           static_cast<std::uint32_t>(y);
  }
  static std::uint64_t key(const Vector2d& p) {
    const auto [x, y] = cell(p);
    return pack(x, y);
  }
  const std::vector<Vector2d>& points_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

/// Two unit vectors orthogonal to `d` and to each other.
std::pair<Vector3d, Vector3d> orthonormalBasis(const Vector3d& d) {
  const Vector3d helper = std::abs(d.z()) < 0.9 ? Vector3d::UnitZ() : Vector3d::UnitX();
  const Vector3d e1 = d.cross(helper).normalized();
  return {e1, d.cross(e1).normalized()};
}

Vector3d randomUnit(Rng& rng) {
  const double z = rng.uniform(-1.0, 1.0);
  const double phi = rng.uniform(0.0, 2.0 * kPi);
  const double s = std::sqrt(1.0 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}

/// A small triangle of size `size_m` with a random orientation: one needle cluster or leaf.
void addFoliageElement(GeometryBuffers& g, Rng& rng, const Vector3d& center, double size_m) {
  const auto [e1, e2] = orthonormalBasis(randomUnit(rng));
  const double s = size_m * rng.uniform(0.7, 1.3);
  g.addTriangle(center + s * e1, center + s * (-0.5 * e1 + 0.866 * e2),
                center + s * (-0.5 * e1 - 0.866 * e2), Material::kFoliage);
}

struct BranchStyle {
  double elevation_rad;  ///< initial angle above the horizontal
  double droop;          ///< downward bend of the tip, fraction of the length
  double foliage_per_m;  ///< foliage elements per metre of branch
  double foliage_size_m;
  double foliage_start;  ///< foliage only beyond this fraction of the length
  Material material = Material::kBranch;
};

void addBranch(GeometryBuffers& g, Rng& rng, const Vector3d& start, double azimuth, double length_m,
               double radius_m, const BranchStyle& style) {
  if (length_m < 0.1) return;
  const Vector3d dir(std::cos(azimuth) * std::cos(style.elevation_rad),
                     std::sin(azimuth) * std::cos(style.elevation_rad),
                     std::sin(style.elevation_rad));
  const Vector3d mid = start + 0.5 * length_m * dir - Vector3d(0, 0, 0.25 * style.droop * length_m);
  const Vector3d end = start + length_m * dir - Vector3d(0, 0, style.droop * length_m);
  g.addCurve({Vector4d(start.x(), start.y(), start.z(), radius_m),
              Vector4d(mid.x(), mid.y(), mid.z(), 0.6 * radius_m),
              Vector4d(end.x(), end.y(), end.z(), std::max(0.003, 0.25 * radius_m))},
             style.material);
  const int n = static_cast<int>(std::round(style.foliage_per_m * length_m));
  for (int i = 0; i < n; ++i) {
    const double f = rng.uniform(style.foliage_start, 1.0);
    const Vector3d on_axis =
        f < 0.5 ? start + 2.0 * f * (mid - start) : mid + (2.0 * f - 1.0) * (end - mid);
    const double spread = 0.08 + 0.2 * f;
    const Vector3d offset(rng.uniform(-spread, spread), rng.uniform(-spread, spread),
                          rng.uniform(-0.5 * spread, 0.5 * spread));
    addFoliageElement(g, rng, on_axis + offset, style.foliage_size_m);
  }
}

void addStem(GeometryBuffers& g, const Tree& stem) {
  std::vector<Vector4d> points;
  auto add = [&](double s) {
    const Vector3d p = stem.axisAt(s);
    points.emplace_back(p.x(), p.y(), p.z(), stem.radiusAt(s));
  };
  for (const double s : {-0.4, 0.0, 0.3, 0.7, 1.3}) add(s);
  const double step = 0.8;
  for (double s = 1.3 + step; s < stem.height_m - 0.05; s += step) add(s);
  add(stem.height_m);
  g.addCurve(points, Material::kBark);
}

/// Stem, branches and foliage of one mature tree; `max_low_branch_m` keeps the path free.
void addTree(GeometryBuffers& g, Rng& rng, const Tree& tree, double max_low_branch_m) {
  const Tree& stem = tree;
  addStem(g, stem);
  const double h = tree.height_m;
  const double hc = tree.crown_base_m;
  double spacing = 0.6, lmax = 2.0;
  int per_whorl = 4;
  BranchStyle style{};
  switch (tree.species) {
    case Species::kPine:
      spacing = 0.6, per_whorl = 4, lmax = rng.uniform(1.5, 2.5);
      style = {15 * kRadPerDeg, 0.1, 3.0, 0.14, 0.4};
      break;
    case Species::kSpruce:
      spacing = 0.5, per_whorl = 4, lmax = rng.uniform(2.0, 3.0);
      style = {-12 * kRadPerDeg, 0.15, 3.0, 0.13, 0.1};
      break;
    case Species::kBirch:
    case Species::kSapling:
      spacing = 0.8, per_whorl = 3, lmax = rng.uniform(1.5, 3.0);
      style = {40 * kRadPerDeg, 0.1, 4.0, 0.08, 0.3};
      break;
  }
  const double phase = rng.uniform(0.0, 2.0 * kPi);
  for (double s = hc; s < h - 0.3; s += spacing * rng.uniform(0.8, 1.2)) {
    const double f = (s - hc) / std::max(h - hc, 0.5);
    double length = lmax;
    if (tree.species == Species::kSpruce) {
      length = 0.2 + lmax * std::pow(1.0 - f, 0.9);
    } else {
      length = lmax * std::pow(std::sin(kPi * (0.15 + 0.85 * f)), 0.6) + 0.2;
    }
    if (s < kHeadZone_m) length = std::min(length, max_low_branch_m);
    for (int b = 0; b < per_whorl; ++b) {
      const double azimuth = phase + 2.0 * kPi * (b + rng.uniform(-0.3, 0.3)) / per_whorl + 2.4 * s;
      const double l = length * rng.uniform(0.75, 1.15);
      const double r = std::min(0.4 * stem.radiusAt(s), 0.01 + 0.01 * l);
      const Vector3d start = stem.axisAt(s);
      addBranch(g, rng, start, azimuth, l, r, style);
    }
  }
  // Dead twigs below the live crown of spruces (and a few on pines): what lidar sees so much of
  // in managed boreal stands.
  const double twig_spacing = tree.species == Species::kSpruce ? 0.4 : 1.2;
  const BranchStyle twig{-5 * kRadPerDeg, 0.05, 0.0, 0.0, 1.0, Material::kDeadWood};
  for (double s = 1.0; s < hc; s += twig_spacing * rng.uniform(0.7, 1.3)) {
    if (tree.species == Species::kBirch) break;
    const int n = rng.uniform(0.0, 1.0) < 0.5 ? 2 : 3;
    for (int b = 0; b < n; ++b) {
      double l = rng.uniform(0.2, 0.9);
      if (s < kHeadZone_m) l = std::min(l, max_low_branch_m);
      addBranch(g, rng, stem.axisAt(s), rng.uniform(0.0, 2.0 * kPi), l, 0.008, twig);
    }
  }
}

void addSapling(GeometryBuffers& g, Rng& rng, const Vector3d& base, double height_m) {
  const double r0 = rng.uniform(0.008, 0.025);
  const Vector3d tip = base + Vector3d(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), height_m);
  const Vector3d mid =
      0.5 * (base + tip) + Vector3d(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), 0);
  g.addCurve(
      {Vector4d(base.x(), base.y(), base.z() - 0.1, r0),
       Vector4d(mid.x(), mid.y(), mid.z(), 0.6 * r0), Vector4d(tip.x(), tip.y(), tip.z(), 0.003)},
      Material::kBranch);
  const BranchStyle style{10 * kRadPerDeg, 0.1, 6.0, 0.07, 0.2};
  for (double s = 0.3 * height_m; s < height_m - 0.1; s += rng.uniform(0.25, 0.45)) {
    const double f = s / height_m;
    const double length = (1.0 - f) * std::min(1.0, 0.35 * height_m) + 0.1;
    for (int b = 0; b < 3; ++b) {
      addBranch(g, rng, base + f * (tip - base), rng.uniform(0.0, 2.0 * kPi), length, 0.005, style);
    }
  }
}

void addShrub(GeometryBuffers& g, Rng& rng, const Terrain& terrain, const Vector2d& center) {
  const double radius = rng.uniform(0.3, 0.8);
  const double top = rng.uniform(0.15, 0.6);
  const int n = static_cast<int>(40 * radius);
  for (int i = 0; i < n; ++i) {
    const double a = rng.uniform(0.0, 2.0 * kPi);
    const double d = radius * std::sqrt(rng.unit());
    const Vector2d p = center + d * Vector2d(std::cos(a), std::sin(a));
    const double z =
        terrain.height(p.x(), p.y()) + top * rng.uniform(0.2, 1.0) * (1.0 - 0.5 * d / radius);
    addFoliageElement(g, rng, Vector3d(p.x(), p.y(), z), rng.uniform(0.04, 0.09));
  }
}

void addBoulder(GeometryBuffers& g, Rng& rng, const Boulder& boulder) {
  // Icosphere, subdivided twice, with a smooth random radial bulge.
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3d> v{{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (Vector3d& p : v) p.normalize();
  for (int level = 0; level < 2; ++level) {
    std::vector<std::array<int, 3>> next;
    std::unordered_map<std::uint64_t, int> midpoints;
    auto midpoint = [&](int a, int b) {
      const std::uint64_t k = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      const auto it = midpoints.find(k);
      if (it != midpoints.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return midpoints[k] = static_cast<int>(v.size() - 1);
    };
    for (const auto& tri : f) {
      const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
                ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  const Vector3d k1 = randomUnit(rng) * rng.uniform(1.5, 3.0),
                 k2 = randomUnit(rng) * rng.uniform(2.0, 4.0);
  const double p1 = rng.uniform(0.0, 6.3), p2 = rng.uniform(0.0, 6.3);
  const Vector3d scale(1.0, rng.uniform(0.7, 1.0), rng.uniform(0.5, 0.8));
  std::vector<std::uint32_t> ids;
  for (const Vector3d& p : v) {
    const double bulge = 1.0 + 0.12 * std::sin(k1.dot(p) + p1) + 0.06 * std::sin(k2.dot(p) + p2);
    ids.push_back(
        g.addVertex(boulder.center_world + boulder.radius_m * bulge * p.cwiseProduct(scale)));
  }
  for (const auto& tri : f) g.addTriangle(ids[tri[0]], ids[tri[1]], ids[tri[2]], Material::kRock);
}

void addGround(GeometryBuffers& g, const Terrain& terrain, const SceneLayout& layout) {
  constexpr double kSpacing_m = 0.5;
  const int n = static_cast<int>(std::ceil(2.0 * layout.half_size_m / kSpacing_m));
  const Vector2d origin = layout.center_world - Vector2d::Constant(layout.half_size_m);
  const auto first = static_cast<std::uint32_t>(g.tri_vertices.size() / 3);
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = origin.x() + i * kSpacing_m, y = origin.y() + j * kSpacing_m;
      g.addVertex(Vector3d(x, y, terrain.height(x, y)));
    }
  }
  const auto id = [&](int i, int j) { return first + static_cast<std::uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      g.addTriangle(id(i, j), id(i + 1, j), id(i + 1, j + 1), Material::kGround);
      g.addTriangle(id(i, j), id(i + 1, j + 1), id(i, j + 1), Material::kGround);
    }
  }
}

Species drawSpecies(Rng& rng, const SpeciesMix& mix) {
  const double total = std::max(1e-9, mix.pine + mix.spruce + mix.birch);
  const double u = rng.unit() * total;
  if (u < mix.pine) return Species::kPine;
  if (u < mix.pine + mix.spruce) return Species::kSpruce;
  return Species::kBirch;
}

}  // namespace

ForestContents buildForest(const ForestParams& params, std::uint64_t seed,
                           const SceneLayout& layout, const Terrain& terrain) {
  ForestContents out;
  GeometryBuffers& g = out.geometry;
  addGround(g, terrain, layout);
  const PathIndex path(layout.keep_out_path);
  const double side_m = 2.0 * layout.half_size_m;
  const double area_ha = side_m * side_m / 1e4;
  const Vector2d lo = layout.center_world - Vector2d::Constant(layout.half_size_m);
  auto randomPoint = [&](Rng& rng) {
    return Vector2d(lo.x() + rng.uniform(0.0, side_m), lo.y() + rng.uniform(0.0, side_m));
  };
  auto onRoad = [&](const Vector2d& p, double margin) {
    return params.road_half_width_m > 0.0 &&
           std::abs(p.y() - layout.center_world.y()) < params.road_half_width_m + margin;
  };

  // Mature trees: dart throwing with a minimum spacing (a regular-ish managed stand).
  Rng rng(streamSeed(seed, "trees"));
  const auto wanted = static_cast<std::size_t>(std::round(params.stems_per_ha * area_ha));
  const double min_spacing_m =
      params.stems_per_ha > 0 ? 0.4 * std::sqrt(1e4 / params.stems_per_ha) : 0.0;
  std::vector<Vector2d> placed;
  for (std::size_t attempt = 0; placed.size() < wanted && attempt < 40 * wanted; ++attempt) {
    const Vector2d p = randomPoint(rng);
    const double dbh = std::clamp(rng.normal(params.dbh_mean_m, params.dbh_sigma_m), 0.08, 0.5);
    const double path_distance = path.distance(p);
    if (path_distance < params.path_clearance_m + 0.5 * dbh || onRoad(p, 0.5 * dbh)) continue;
    bool crowded = false;
    for (const Vector2d& q : placed) {
      if ((q - p).squaredNorm() < min_spacing_m * min_spacing_m) {
        crowded = true;
        break;
      }
    }
    if (crowded) continue;
    placed.push_back(p);
    Tree tree;
    tree.species = drawSpecies(rng, params.species);
    tree.base_world = Vector3d(p.x(), p.y(), terrain.height(p.x(), p.y()));
    tree.dbh_m = dbh;
    tree.height_m = std::clamp(
        10.0 + 18.0 * std::pow((dbh - 0.08) / 0.42, 0.6) + rng.normal(0.0, 1.5), 10.0, 28.0);
    tree.lean_rad = std::min(std::abs(rng.normal(0.0, 2.5 * kRadPerDeg)), 8.0 * kRadPerDeg);
    tree.lean_azimuth_rad = rng.uniform(0.0, 2.0 * kPi);
    const double crown_fraction = tree.species == Species::kPine     ? rng.uniform(0.5, 0.7)
                                  : tree.species == Species::kSpruce ? rng.uniform(0.1, 0.3)
                                                                     : rng.uniform(0.4, 0.6);
    tree.crown_base_m = crown_fraction * tree.height_m;
    tree.bend_m = rng.uniform(0.0, 0.01) * tree.height_m;
    tree.bend_azimuth_rad = rng.uniform(0.0, 2.0 * kPi);
    addTree(g, rng, tree, std::max(0.0, path_distance - 0.9));
    out.trees.push_back(tree);
  }

  Rng under(streamSeed(seed, "undergrowth"));
  const auto saplings = static_cast<std::size_t>(std::round(params.saplings_per_ha * area_ha));
  for (std::size_t i = 0; i < saplings; ++i) {
    const Vector2d p = randomPoint(under);
    const double height = under.uniform(0.5, 4.0);
    if (path.distance(p) < 1.5 || onRoad(p, 0.0)) continue;
    addSapling(g, under, Vector3d(p.x(), p.y(), terrain.height(p.x(), p.y())), height);
  }
  const auto shrubs = static_cast<std::size_t>(std::round(params.shrubs_per_ha * area_ha));
  for (std::size_t i = 0; i < shrubs; ++i) addShrub(g, under, terrain, randomPoint(under));

  Rng rocks(streamSeed(seed, "boulders"));
  const auto boulders = static_cast<std::size_t>(std::round(params.boulders_per_ha * area_ha));
  for (std::size_t i = 0; i < boulders; ++i) {
    const Vector2d p = randomPoint(rocks);
    const double radius = rocks.uniform(0.3, 1.5) * 0.5 + (rocks.bernoulli(0.2) ? 0.5 : 0.0);
    if (path.distance(p) < radius + 0.8) continue;
    Boulder b{Vector3d(p.x(), p.y(), terrain.height(p.x(), p.y()) - 0.3 * radius), radius};
    addBoulder(g, rocks, b);
    out.boulders.push_back(b);
  }
  const auto logs = static_cast<std::size_t>(std::round(params.logs_per_ha * area_ha));
  for (std::size_t i = 0; i < logs; ++i) {
    const Vector2d a = randomPoint(rocks);
    const double length = rocks.uniform(3.0, 12.0), azimuth = rocks.uniform(0.0, 2.0 * kPi);
    const double radius = rocks.uniform(0.08, 0.25);
    const Vector2d b = a + length * Vector2d(std::cos(azimuth), std::sin(azimuth));
    std::vector<Vector4d> points;
    const int n = static_cast<int>(std::ceil(length));
    for (int k = 0; k <= n; ++k) {
      const Vector2d p = a + (b - a) * (static_cast<double>(k) / n);
      const double r = radius * (1.0 - 0.4 * k / n);
      points.emplace_back(p.x(), p.y(), terrain.height(p.x(), p.y()) + 0.7 * r, r);
    }
    g.addCurve(points, Material::kDeadWood);
    out.logs.push_back({points.front().head<3>(), points.back().head<3>(), radius});
  }
  return out;
}

}  // namespace taiga::sim::detail
