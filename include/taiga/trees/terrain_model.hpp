#pragma once
// The ground under a forest map: which points are ground and a digital terrain model (DTM) that
// gives every point its height above the ground (docs/trees.md, "Ground and terrain").
//
// Method: the lowest point of each grid cell, then a progressive morphological filter (Zhang et
// al. 2003, IEEE TGRS 41(4)): openings (erosion, then dilation) of that lowest surface with
// growing square windows; a cell whose lowest point stands above the opened surface by more than
// dh_k = dh_0 + slope * (w_k - w_(k-1)) is not ground (a boulder, a log, a bush, a machine:
// anything narrower than the window is opened away, while the threshold growing with the window
// keeps a slope). The ground cells' heights (the mean of their points within 0.1 m of the lowest,
// so the lowest noisy point does not bias the terrain low) are filled into the other cells from
// their neighbours, and the DTM is read bilinearly between cell centres.

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <span>
#include <vector>

namespace taiga::trees {

struct TerrainOptions {
  double cell_m = 0.5;
  /// The largest window, m: wider than the widest non-ground object on the ground (boulders,
  /// root plates, a harvester) and narrower than the terrain's features.
  double max_window_m = 16.0;
  double slope = 0.7;                ///< the steepest terrain slope kept as ground (rise / run)
  double initial_threshold_m = 0.2;  ///< dh_0
  double max_threshold_m = 2.5;
  double ground_band_m = 0.15;  ///< a point within this height of the DTM is a ground point
};

class TerrainModel {
 public:
  TerrainModel() = default;
  TerrainModel(Eigen::Vector2d origin_m, double cell_m, int nx, int ny, std::vector<double> z_m,
               std::vector<bool> measured);

  /// The terrain height at (x, y), bilinear between cell centres; the nearest edge cell outside.
  double heightAt(double x_m, double y_m) const;
  /// Whether the cell holding (x, y) had ground points of its own (not filled from neighbours).
  bool measuredAt(double x_m, double y_m) const;
  bool empty() const { return z_m_.empty(); }

  const Eigen::Vector2d& origin() const { return origin_m_; }  ///< corner of cell (0, 0)
  double cellSize() const { return cell_m_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double cellHeight(int ix, int iy) const { return z_m_[index(ix, iy)]; }
  bool cellMeasured(int ix, int iy) const { return measured_[index(ix, iy)]; }
  std::size_t measuredCells() const;

 private:
  std::size_t index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(ix);
  }
  Eigen::Vector2d origin_m_ = Eigen::Vector2d::Zero();
  double cell_m_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<double> z_m_;
  std::vector<bool> measured_;
};

/// The terrain of `points_m` (local coordinates, m; non-finite points are skipped). InputError
/// when there are no finite points or they span more than 5 km.
TerrainModel buildTerrainModel(std::span<const Eigen::Vector3d> points_m,
                               const TerrainOptions& options = {});

/// Writes the DTM as a plain-text grid (ESRI ASCII grid, which QGIS and GDAL read): ncols,
/// nrows, xllcorner, yllcorner, cellsize, NODATA_value, then rows from north to south.
/// `offset_m` is added to the coordinates (the origin the points were shifted by); cells that
/// were only filled from neighbours are written as measured too, unless `filled_as_nodata`.
void writeAsciiGrid(const std::filesystem::path& path, const TerrainModel& terrain,
                    const Eigen::Vector3d& offset_m, bool filled_as_nodata = false);

}  // namespace taiga::trees
