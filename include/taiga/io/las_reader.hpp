#pragma once
// Reading LAS point records (ASPRS LAS 1.2-1.4, point formats 0-10), streamed: the header is
// parsed on open and points are read in chunks or at a stride, so maps larger than RAM can be
// sampled (the map sharpness score reads a few hundred thousand points of map.las).
// Read: coordinates (scale and offset applied), intensity, user data (taiga writes the ring
// there), point source ID and, for formats with one, GPS time.
// Errors are InputErrors naming the file and the field (signature, version, format, sizes).

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <vector>

#include "taiga/core/point_cloud.hpp"

namespace taiga::io {

struct LasHeader {
  int version_minor = 4;
  std::uint8_t point_format = 6;
  std::uint16_t record_length = 30;
  std::uint32_t point_data_offset = 0;
  std::uint64_t point_count = 0;
  Eigen::Vector3d scale_m = Eigen::Vector3d::Constant(0.001);
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero(), max_m = Eigen::Vector3d::Zero();
};

/// Parses the public header block (the first 227 bytes; 375 for LAS 1.4). `file_size` checks
/// that the announced records fit; `source_name` names the file in messages.
LasHeader parseLasHeader(std::string_view bytes, std::uint64_t file_size,
                         std::string_view source_name);

/// Points of consecutive records; `source_ids` (optional) receives each point source ID.
void decodeLasRecords(const LasHeader& header, std::string_view records, PointCloud& into,
                      std::vector<std::uint16_t>* source_ids = nullptr);

class LasReader {
 public:
  explicit LasReader(const std::filesystem::path& path);
  const LasHeader& header() const { return header_; }
  std::uint64_t pointCount() const { return header_.point_count; }

  /// Appends the points [first, first + count) (clipped to the file) to `into`.
  void read(std::uint64_t first, std::uint64_t count, PointCloud& into,
            std::vector<std::uint16_t>* source_ids = nullptr);
  /// Every `stride`-th point, starting at the first (stride >= 1), read chunk by chunk.
  PointCloud readStrided(std::uint64_t stride, std::vector<std::uint16_t>* source_ids = nullptr);

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  LasHeader header_;
};

}  // namespace taiga::io
