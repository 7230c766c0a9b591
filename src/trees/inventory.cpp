#include "taiga/trees/inventory.hpp"

#include <algorithm>
#include <cmath>

namespace taiga::trees {

Inventory takeInventory(std::span<const Eigen::Vector3d> points_m, const InventoryOptions& options,
                        const Viewpoints& viewpoints) {
  Inventory inventory;
  inventory.terrain = buildTerrainModel(points_m, options.terrain);
  inventory.stems = detectStems(points_m, inventory.terrain, options.stems, viewpoints);
  return inventory;
}

PointLabels labelPoints(std::span<const Eigen::Vector3d> points_m, const Inventory& inventory,
                        const TerrainOptions& terrain_options) {
  const std::vector<std::uint32_t> member =
      stemMembership(points_m, inventory.terrain, inventory.stems);
  PointLabels labels;
  labels.classification.resize(points_m.size(), kClassOther);
  labels.tree_id.resize(points_m.size(), 0);
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const Eigen::Vector3d& p = points_m[i];
    if (!p.allFinite()) continue;
    if (member[i] > 0) {
      labels.classification[i] = kClassStem;
      labels.tree_id[i] = static_cast<std::uint16_t>(std::min<std::uint32_t>(member[i], 65535));
    } else if (std::abs(p.z() - inventory.terrain.heightAt(p.x(), p.y())) <
               terrain_options.ground_band_m) {
      labels.classification[i] = kClassGround;
    }
  }
  return labels;
}

}  // namespace taiga::trees
