#pragma once
// Geometry of a scene as flat buffers in Embree's layouts: triangles (float3 vertices, uint3
// indices) and cone linear curves (float4 x y z radius vertices, one uint index per segment).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "taiga/sim/scene.hpp"

namespace taiga::sim::detail {

struct GeometryBuffers {
  std::vector<float> tri_vertices;  ///< x y z per vertex
  std::vector<std::uint32_t> tri_indices;
  std::vector<Material> tri_materials;
  std::vector<float> curve_vertices;  ///< x y z radius per vertex
  std::vector<std::uint32_t> curve_indices;
  std::vector<Material> curve_materials;

  std::uint32_t addVertex(const Eigen::Vector3d& p) {
    const auto index = static_cast<std::uint32_t>(tri_vertices.size() / 3);
    tri_vertices.insert(tri_vertices.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()),
                                             static_cast<float>(p.z())});
    return index;
  }
  void addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, Material material) {
    tri_indices.insert(tri_indices.end(), {a, b, c});
    tri_materials.push_back(material);
  }
  void addTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   Material material) {
    addTriangle(addVertex(a), addVertex(b), addVertex(c), material);
  }
  /// A chain of cones through `points` (x y z radius).
  void addCurve(const std::vector<Eigen::Vector4d>& points, Material material) {
    if (points.size() < 2) return;
    const auto first = static_cast<std::uint32_t>(curve_vertices.size() / 4);
    for (const Eigen::Vector4d& p : points) {
      curve_vertices.insert(curve_vertices.end(),
                            {static_cast<float>(p[0]), static_cast<float>(p[1]),
                             static_cast<float>(p[2]), static_cast<float>(p[3])});
    }
    for (std::uint32_t i = 0; i + 1 < points.size(); ++i) {
      curve_indices.push_back(first + i);
      curve_materials.push_back(material);
    }
  }
  std::size_t triangleCount() const { return tri_materials.size(); }
  std::size_t curveSegmentCount() const { return curve_materials.size(); }
};

struct ForestContents {
  std::vector<Tree> trees;
  std::vector<Boulder> boulders;
  std::vector<FallenLog> logs;
  GeometryBuffers geometry;
};

/// Generates every object of the plot; deterministic in (params, seed, layout).
ForestContents buildForest(const ForestParams& params, std::uint64_t seed,
                           const SceneLayout& layout, const Terrain& terrain);

}  // namespace taiga::sim::detail
