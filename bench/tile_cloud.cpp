// Makes a large map from a small one for the viewer's benchmark (bench/viewer.sh): the cloud is
// laid out in a square grid of copies side by side, until about TARGET points, and written as
// LAS. Usage: tile_cloud IN.las TARGET_POINTS OUT.las
#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "taiga/io/las_reader.hpp"
#include "taiga/io/las_writer.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    fmt::print(stderr, "usage: tile_cloud IN.las TARGET_POINTS OUT.las\n");
    return 2;
  }
  taiga::io::LasReader reader(argv[1]);
  taiga::PointCloud tile;
  reader.read(0, reader.pointCount(), tile);
  const double target = std::atof(argv[2]);
  const int copies = std::max(1, static_cast<int>(std::lround(target / tile.size())));
  const int side = static_cast<int>(std::ceil(std::sqrt(copies)));
  Eigen::Vector3d min = tile.positions.front(), max = min;
  for (const Eigen::Vector3d& p : tile.positions) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  const Eigen::Vector3d step = max - min;
  taiga::io::LasWriter writer(argv[3]);
  for (int k = 0; k < copies; ++k) {
    taiga::PointCloud copy = tile;
    const Eigen::Vector3d shift(step.x() * (k % side), step.y() * (k / side), 0.0);
    for (Eigen::Vector3d& p : copy.positions) p += shift;
    writer.append(copy);
  }
  writer.close();
  fmt::print("{} copies of {} points: {} points in {}\n", copies, tile.size(), writer.pointCount(),
             argv[3]);
  return 0;
}
