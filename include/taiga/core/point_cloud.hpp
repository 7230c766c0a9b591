#pragma once
// A point cloud as a structure of arrays. Positions are always present; the other channels are
// either empty (the sensor does not provide them) or exactly as long as `positions`.
// The frame of the positions is named by the variable that holds the cloud (`cloud_in_lidar`,
// `cloud_in_body`, `cloud_in_world`).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace taiga {

struct PointCloud {
  std::vector<Eigen::Vector3d> positions;  ///< m
  std::vector<double> times_s;             ///< absolute per-point time on the recording's clock
  std::vector<float> intensities;          ///< sensor units (e.g. Ouster reflectivity)
  std::vector<std::uint16_t> rings;        ///< beam (row) index, 0 = first beam of the sensor
  std::vector<std::uint16_t> columns;      ///< column (azimuth) index within the scan

  std::size_t size() const { return positions.size(); }
  bool empty() const { return positions.empty(); }
  bool hasTimes() const { return !times_s.empty(); }
  bool hasIntensities() const { return !intensities.empty(); }
  bool hasRings() const { return !rings.empty(); }
  bool hasColumns() const { return !columns.empty(); }

  /// True when every non-empty channel has one entry per position.
  bool isConsistent() const;
  /// Empties every channel, keeping which channels exist is up to the next writer.
  void clear();
  void reserve(std::size_t n);
  /// Appends `other`; both clouds must carry the same channels (or this one must be empty).
  void append(const PointCloud& other);
  /// The points at `indices`, in that order, with all channels.
  PointCloud select(std::span<const std::size_t> indices) const;
  /// Keeps, in place and in order, the points whose `keep` entry (one per point) is non-zero,
  /// with all channels.
  void keepWhere(std::span<const std::uint8_t> keep);
  /// Earliest and latest per-point time; requires hasTimes() and a non-empty cloud.
  std::pair<double, double> timeSpan() const;
};

}  // namespace taiga
