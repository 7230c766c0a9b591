#pragma once
// The forest inventory of a point cloud in one call: terrain, stems, and each point's class and
// tree (docs/trees.md). `taiga trees` is this plus file input and output.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "taiga/trees/stem_detection.hpp"
#include "taiga/trees/terrain_model.hpp"

namespace taiga::trees {

/// ASPRS LAS 1.4 classification codes written per point (64 is the first user-definable code;
/// LAS has no code for stems).
inline constexpr std::uint8_t kClassOther = 1;
inline constexpr std::uint8_t kClassGround = 2;
inline constexpr std::uint8_t kClassStem = 64;

struct InventoryOptions {
  TerrainOptions terrain;
  StemOptions stems;
};

struct Inventory {
  TerrainModel terrain;
  std::vector<Stem> stems;
};

/// Terrain and stems of `points_m` (local coordinates: subtract a large offset first);
/// `viewpoints` as in detectStems.
Inventory takeInventory(std::span<const Eigen::Vector3d> points_m,
                        const InventoryOptions& options = {}, const Viewpoints& viewpoints = {});

struct PointLabels {
  std::vector<std::uint8_t> classification;  ///< kClassGround, kClassStem or kClassOther
  std::vector<std::uint16_t> tree_id;        ///< 0: no tree; else the stem's index + 1
};

/// Each point's class: on a stem (stemMembership), else ground when within the terrain options'
/// ground band of the DTM, else other.
PointLabels labelPoints(std::span<const Eigen::Vector3d> points_m, const Inventory& inventory,
                        const TerrainOptions& terrain_options = {});

}  // namespace taiga::trees
