#include "taiga/trees/terrain_model.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "taiga/core/errors.hpp"

namespace taiga::trees {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMaxSpan_m = 5000.0;

struct Grid {
  Eigen::Vector2d origin_m;
  double cell_m = 1.0;
  int nx = 0, ny = 0;
  std::size_t at(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx) +
           static_cast<std::size_t>(ix);
  }
  std::size_t cells() const { return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny); }
  bool cellOf(const Eigen::Vector3d& p, std::size_t& index) const {
    const int ix = static_cast<int>(std::floor((p.x() - origin_m.x()) / cell_m));
    const int iy = static_cast<int>(std::floor((p.y() - origin_m.y()) / cell_m));
    if (ix < 0 || iy < 0 || ix >= nx || iy >= ny) return false;
    index = at(ix, iy);
    return true;
  }
};

Grid gridAround(std::span<const Eigen::Vector3d> points_m, double cell_m) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector3d& p : points_m) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  if (!(lo.array() <= hi.array()).all())
    throw InputError("the cloud has no finite points: no terrain to model");
  const Eigen::Vector2d span = hi - lo;
  if (span.maxCoeff() > kMaxSpan_m)
    throw InputError(fmt::format(
        "the cloud spans {:.0f} x {:.0f} m; the terrain model covers at most {:.0f} m (crop it, "
        "or look for stray points far from the rest)",
        span.x(), span.y(), kMaxSpan_m));
  Grid grid;
  grid.origin_m = lo;
  grid.cell_m = cell_m;
  grid.nx = static_cast<int>(std::floor(span.x() / cell_m)) + 1;
  grid.ny = static_cast<int>(std::floor(span.y() / cell_m)) + 1;
  return grid;
}

// Minimum (erosion) or maximum (dilation) over a square window of half-size r cells, ignoring
// empty (NaN) cells; separable, rows then columns.
std::vector<double> morph(const Grid& g, const std::vector<double>& z, int r, bool take_min) {
  auto better = [take_min](double a, double b) {
    if (std::isnan(a)) return b;
    if (std::isnan(b)) return a;
    return take_min ? std::min(a, b) : std::max(a, b);
  };
  std::vector<double> rows(z.size(), kNaN), out(z.size(), kNaN);
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      double v = kNaN;
      for (int k = std::max(0, ix - r); k <= std::min(g.nx - 1, ix + r); ++k)
        v = better(v, z[g.at(k, iy)]);
      rows[g.at(ix, iy)] = v;
    }
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix) {
      double v = kNaN;
      for (int k = std::max(0, iy - r); k <= std::min(g.ny - 1, iy + r); ++k)
        v = better(v, rows[g.at(ix, k)]);
      out[g.at(ix, iy)] = v;
    }
  return out;
}

// Zhang et al. 2003: true for cells whose lowest point is ground.
std::vector<bool> progressiveMorphologicalFilter(const Grid& g, const std::vector<double>& z_min,
                                                 const TerrainOptions& o) {
  std::vector<bool> ground(z_min.size());
  for (std::size_t i = 0; i < z_min.size(); ++i) ground[i] = !std::isnan(z_min[i]);
  std::vector<double> surface = z_min;
  int previous_window = 1;
  for (int r = 1; (2 * r + 1) * o.cell_m <= o.max_window_m || r == 1; r *= 2) {
    const int window = 2 * r + 1;
    const double threshold_m = std::min(
        o.max_threshold_m, o.initial_threshold_m + o.slope * (window - previous_window) * o.cell_m);
    surface = morph(g, morph(g, surface, r, true), r, false);
    for (std::size_t i = 0; i < z_min.size(); ++i)
      if (ground[i] && z_min[i] - surface[i] > threshold_m) ground[i] = false;
    previous_window = window;
  }
  return ground;
}

// Cells without ground take the mean of their already-known 8-neighbours, in breadth-first order
// from the ground cells (so a large gap is filled from its rim inwards, in one pass).
void fillFromNeighbours(const Grid& g, std::vector<double>& z) {
  std::deque<std::size_t> queue;
  std::vector<bool> queued(z.size(), false);
  for (std::size_t i = 0; i < z.size(); ++i)
    if (!std::isnan(z[i])) queued[i] = true;
  auto pushNeighbours = [&](int ix, int iy) {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = ix + dx, y = iy + dy;
        if (x < 0 || y < 0 || x >= g.nx || y >= g.ny || queued[g.at(x, y)]) continue;
        queued[g.at(x, y)] = true;
        queue.push_back(g.at(x, y));
      }
  };
  for (int iy = 0; iy < g.ny; ++iy)
    for (int ix = 0; ix < g.nx; ++ix)
      if (!std::isnan(z[g.at(ix, iy)])) pushNeighbours(ix, iy);
  while (!queue.empty()) {
    const std::size_t i = queue.front();
    queue.pop_front();
    const int ix = static_cast<int>(i % static_cast<std::size_t>(g.nx));
    const int iy = static_cast<int>(i / static_cast<std::size_t>(g.nx));
    double sum = 0.0;
    int n = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = ix + dx, y = iy + dy;
        if (x < 0 || y < 0 || x >= g.nx || y >= g.ny || std::isnan(z[g.at(x, y)])) continue;
        sum += z[g.at(x, y)];
        ++n;
      }
    if (n > 0) z[i] = sum / n;
    pushNeighbours(ix, iy);
  }
}

}  // namespace

TerrainModel::TerrainModel(Eigen::Vector2d origin_m, double cell_m, int nx, int ny,
                           std::vector<double> z_m, std::vector<bool> measured)
    : origin_m_(std::move(origin_m)),
      cell_m_(cell_m),
      nx_(nx),
      ny_(ny),
      z_m_(std::move(z_m)),
      measured_(std::move(measured)) {}

double TerrainModel::heightAt(double x_m, double y_m) const {
  // Bilinear between cell centres, clamped to the grid.
  const double fx = std::clamp((x_m - origin_m_.x()) / cell_m_ - 0.5, 0.0, nx_ - 1.0);
  const double fy = std::clamp((y_m - origin_m_.y()) / cell_m_ - 0.5, 0.0, ny_ - 1.0);
  const int ix = std::min(static_cast<int>(fx), std::max(0, nx_ - 2));
  const int iy = std::min(static_cast<int>(fy), std::max(0, ny_ - 2));
  const int jx = std::min(ix + 1, nx_ - 1), jy = std::min(iy + 1, ny_ - 1);
  const double ax = fx - ix, ay = fy - iy;
  return (1 - ay) * ((1 - ax) * z_m_[index(ix, iy)] + ax * z_m_[index(jx, iy)]) +
         ay * ((1 - ax) * z_m_[index(ix, jy)] + ax * z_m_[index(jx, jy)]);
}

bool TerrainModel::measuredAt(double x_m, double y_m) const {
  const int ix = static_cast<int>(std::floor((x_m - origin_m_.x()) / cell_m_));
  const int iy = static_cast<int>(std::floor((y_m - origin_m_.y()) / cell_m_));
  return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_ && measured_[index(ix, iy)];
}

std::size_t TerrainModel::measuredCells() const {
  return static_cast<std::size_t>(std::count(measured_.begin(), measured_.end(), true));
}

TerrainModel buildTerrainModel(std::span<const Eigen::Vector3d> points_m,
                               const TerrainOptions& options) {
  const Grid grid = gridAround(points_m, options.cell_m);
  std::vector<double> z_min(grid.cells(), kNaN);
  std::size_t cell = 0;
  for (const Eigen::Vector3d& p : points_m)
    if (p.allFinite() && grid.cellOf(p, cell) && !(z_min[cell] <= p.z())) z_min[cell] = p.z();

  const std::vector<bool> ground = progressiveMorphologicalFilter(grid, z_min, options);
  // A ground cell's height: the mean of its points within 0.1 m of its lowest one.
  std::vector<double> sum(grid.cells(), 0.0);
  std::vector<std::uint32_t> count(grid.cells(), 0);
  for (const Eigen::Vector3d& p : points_m) {
    if (!p.allFinite() || !grid.cellOf(p, cell) || !ground[cell] || p.z() > z_min[cell] + 0.1)
      continue;
    sum[cell] += p.z();
    ++count[cell];
  }
  std::vector<double> z(grid.cells(), kNaN);
  for (std::size_t i = 0; i < z.size(); ++i)
    if (ground[i]) z[i] = sum[i] / count[i];
  fillFromNeighbours(grid, z);
  return TerrainModel(grid.origin_m, grid.cell_m, grid.nx, grid.ny, std::move(z), ground);
}

void writeAsciiGrid(const std::filesystem::path& path, const TerrainModel& terrain,
                    const Eigen::Vector3d& offset_m, bool filled_as_nodata) {
  auto out = fmt::output_file(path.string());
  out.print(
      "ncols {}\nnrows {}\nxllcorner {:.3f}\nyllcorner {:.3f}\ncellsize {}\n"
      "NODATA_value -9999\n",
      terrain.nx(), terrain.ny(), terrain.origin().x() + offset_m.x(),
      terrain.origin().y() + offset_m.y(), terrain.cellSize());
  for (int iy = terrain.ny() - 1; iy >= 0; --iy) {
    for (int ix = 0; ix < terrain.nx(); ++ix) {
      const bool nodata = filled_as_nodata && !terrain.cellMeasured(ix, iy);
      out.print("{}{:.3f}", ix == 0 ? "" : " ",
                nodata ? -9999.0 : terrain.cellHeight(ix, iy) + offset_m.z());
    }
    out.print("\n");
  }
}

}  // namespace taiga::trees
