#pragma once
// A generated forest plot and ray casting into it (Embree 3).
//
// The plot is an axis-aligned square in the world frame (x east, y north, z up). Its geometry:
// - ground: a triangle mesh (0.5 m grid) of Terrain::height, micro-relief included;
// - stems, branches, twigs, sapling stems and fallen logs: Embree cone linear curves (chains of
//   cones with a radius per vertex);
// - needles and leaves: many small triangles around the branches, shrubs as clumps of triangles;
// - boulders: perturbed, half-buried icospheres.
// The truth a test can measure against (stem positions, DBH, heights, lean) is in trees().

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "taiga/sim/scenario.hpp"
#include "taiga/sim/terrain.hpp"
#include "taiga/sim/wind.hpp"

namespace taiga::sim {

enum class Species : std::uint8_t { kPine, kSpruce, kBirch, kSapling };
enum class Material : std::uint8_t {
  kGround,
  kBark,
  kBranch,
  kFoliage,
  kRock,
  kDeadWood,
  kMachine,  ///< the harvester's painted steel (cabin, crane), see machine.hpp
};

/// Reflectivity of a material at the lidar's 865 nm, in [0, 1].
double reflectivity(Material material);

struct Tree {
  Eigen::Vector3d base_world;     ///< stem axis at the ground (terrain height at the stem), m
  double dbh_m = 0.0;             ///< stem diameter at 1.3 m above the base, m
  double height_m = 0.0;          ///< top height above the base, m
  double lean_rad = 0.0;          ///< angle of the stem axis from the vertical (base to top)
  double lean_azimuth_rad = 0.0;  ///< direction of the lean, from +x towards +y
  double crown_base_m = 0.0;      ///< height of the lowest live branch above the base, m
  /// Sideways bow of the stem: the axis is displaced by bend_m * sin(pi s / height) towards
  /// bend_azimuth_rad at height s (zero at the base and the top).
  double bend_m = 0.0;
  double bend_azimuth_rad = 0.0;
  Species species = Species::kPine;

  /// Stem axis at height s above the base (s may be slightly negative: below ground), world frame.
  Eigen::Vector3d axisAt(double s_m) const;
  /// Stem radius at height s: DBH / 2 at 1.3 m, a butt swell below, tapering to the top.
  double radiusAt(double s_m) const;
};

struct Boulder {
  Eigen::Vector3d center_world;
  double radius_m = 0.0;
};

struct FallenLog {
  Eigen::Vector3d start_world;
  Eigen::Vector3d end_world;
  double radius_m = 0.0;
};

/// The plot area and the path the operator walks (kept free of stems and rocks).
struct SceneLayout {
  Eigen::Vector2d center_world = Eigen::Vector2d::Zero();
  double half_size_m = 60.0;
  std::vector<Eigen::Vector2d> keep_out_path;  ///< polyline, points every ~0.5 m
};

struct RayHit {
  double range_m = 0.0;          ///< distance along the (unit) ray direction, m
  Eigen::Vector3d normal_world;  ///< unit surface normal facing the ray origin
  Material material = Material::kGround;
  /// Index of the curve segment hit (for Scene::curveSegment), or -1 for a triangle or anything
  /// that is not part of the scene (the harvester's own body).
  std::int32_t curve_segment = -1;
};

/// One cone of a linear curve (stem, branch, twig, sapling, log): the axis from a to b
/// with the radius interpolated linearly from radius_a to radius_b.
struct CurveSegment {
  Eigen::Vector3d a_world, b_world;
  double radius_a_m = 0.0, radius_b_m = 0.0;
  bool continues_before = false;  ///< the chain goes on beyond a (a is not a free end)
  bool continues_after = false;   ///< the chain goes on beyond b
};

struct SceneStats {
  std::size_t triangles = 0;
  std::size_t curve_segments = 0;
  double area_ha = 0.0;
};

class Scene {
 public:
  /// Generates the plot: the same params, seed and layout give the same scene.
  Scene(const ForestParams& params, std::uint64_t seed, SceneLayout layout);
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  /// Nearest hit along origin + t * direction (direction of unit length), t in (t_min, t_max).
  /// Thread-safe.
  std::optional<RayHit> castRay(const Eigen::Vector3d& origin_world,
                                const Eigen::Vector3d& direction_world, double t_min_m,
                                double t_max_m) const;

  /// Nearest hits of rays that share an origin (e.g. one lidar column), in packets of 16
  /// (Embree rtcIntersect16): hits[i] for directions[i], searched from (*t_min_m)[i] (0 when
  /// t_min_m is null) to t_max_m. Same results as castRay. Thread-safe.
  void castRays(const Eigen::Vector3d& origin_world,
                const std::vector<Eigen::Vector3d>& directions_world, double t_max_m,
                std::vector<std::optional<RayHit>>& hits,
                const std::vector<double>* t_min_m = nullptr) const;

  /// Unsigned distance from a point to the nearest scene surface, m, or max_distance_m when
  /// nothing is closer. Curves count as cones (radius interpolated along each segment) closed
  /// by flat end discs, as Embree casts them. Thread-safe.
  double distanceToSurface(const Eigen::Vector3d& p_world, double max_distance_m = 5.0) const;

  /// The curve segment with the given index (RayHit::curve_segment); index must be valid.
  CurveSegment curveSegment(std::int32_t index) const;

  const Terrain& terrain() const;
  const Wind& wind() const;  ///< how the stems and crowns sway (calm unless wind_sway_m > 0)
  const SceneLayout& layout() const;
  const std::vector<Tree>& trees() const;
  const std::vector<Boulder>& boulders() const;
  const std::vector<FallenLog>& logs() const;
  SceneStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace taiga::sim
