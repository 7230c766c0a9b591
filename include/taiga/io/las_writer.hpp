#pragma once
// LAS 1.4 output (ASPRS LAS Specification 1.4 R15), point data record format 6: coordinates as
// 32-bit integers with a scale and an offset, intensity, return 1 of 1, classification, GPS time.
//
// The writer streams: points are appended chunk by chunk and the header (counts, bounds) is
// completed on close, so maps of any size are written without holding them in memory.
// Field mapping: point time -> GPS time (s, as on the recording's clock), intensity -> intensity
// (clamped to 0..65535), ring -> user data (0..255), a caller-given id (e.g. the keyframe) ->
// point source ID. With a WKT string the file carries an OGC WKT coordinate-system record and the
// WKT bit of the global encoding, as LAS 1.4 requires for formats 6 and above.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <string>

#include "taiga/core/point_cloud.hpp"

namespace taiga::io {

struct LasOptions {
  /// Coordinate resolution, m. 1 mm keeps projected coordinates (millions of metres) exact to the
  /// millimetre within the 32-bit range around the offset (+-2147 km).
  double scale_m = 0.001;
  /// Subtracted before scaling; default: the first chunk's minimum rounded down to 1 km.
  std::optional<Eigen::Vector3d> offset_m;
  /// OGC WKT of the coordinate system (e.g. EPSG:3067); empty for local coordinates.
  std::string wkt;
  std::string system_identifier = "taiga";
  std::string generating_software = "taiga";
  /// Non-empty: one float32 per point after the standard fields, described by a LAS 1.4 Extra
  /// Bytes VLR with this name (at most 31 characters, e.g. "HeightAboveGround") and description.
  std::string extra_float_name, extra_float_description;
  /// ASPRS class written for every point (1 = unclassified).
  std::uint8_t classification = 1;
};

/// Per-point fields beyond the cloud's channels.
struct LasPointFields {
  std::span<const std::uint8_t> classifications;  ///< ASPRS class
  std::span<const std::uint16_t> source_ids;      ///< point source ID
  /// Return number and the pulse's number of returns (1-15), e.g. {1, 2} and {2, 2} for the
  /// first and last of two (multi-return sensors, airborne lidar).
  std::span<const std::array<std::uint8_t, 2>> returns;
  std::span<const float> extra;  ///< the LasOptions::extra_float field's value
};

class LasWriter {
 public:
  LasWriter(const std::filesystem::path& path, LasOptions options = {});
  ~LasWriter();
  LasWriter(const LasWriter&) = delete;
  LasWriter& operator=(const LasWriter&) = delete;

  /// Appends the points of `cloud` (positions in the output coordinate system). `source_id` goes
  /// to each point's point source ID. Throws InputError when a point does not fit the 32-bit
  /// integer range at the chosen scale and offset.
  void append(const PointCloud& cloud, std::uint16_t source_id = 0);
  /// The same with a classification and a point source ID per point (e.g. ground and stem codes
  /// and tree ids from `taiga trees`); both spans as long as the cloud.
  void append(const PointCloud& cloud, std::span<const std::uint8_t> classifications,
              std::span<const std::uint16_t> source_ids);
  /// The same with any per-point field; an empty span takes the default (class
  /// LasOptions::classification, source ID 0, return 1 of 1, extra value 0); a given one must be
  /// as long as the cloud.
  void append(const PointCloud& cloud, const LasPointFields& fields);
  /// Writes the final header; also done by the destructor (which cannot report errors).
  void close();

  std::uint64_t pointCount() const { return count_; }
  const Eigen::Vector3d& offset() const { return offset_m_; }

 private:
  void writeHeader();
  void appendRecords(const PointCloud& cloud, const LasPointFields& fields,
                     std::uint16_t source_id);

  std::filesystem::path path_;
  LasOptions options_;
  std::ofstream out_;
  Eigen::Vector3d offset_m_ = Eigen::Vector3d::Zero();
  bool offset_set_ = false;
  std::uint64_t count_ = 0;
  std::array<std::uint64_t, 15> points_by_return_{};
  Eigen::Vector3d min_m_, max_m_;
  std::uint32_t point_data_offset_ = 0;
  bool closed_ = false;
};

}  // namespace taiga::io
