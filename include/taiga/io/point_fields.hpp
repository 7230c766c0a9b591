#pragma once
// Decoding packed point records described by named fields: the layout of ROS sensor_msgs/
// PointCloud2, of PCD files and of binary PLY vertices. One decoder serves all of them, so the
// drivers' conventions for per-point time are interpreted in one place:
//
//   field         type           meaning                                       driver
//   t             uint32         ns after the cloud's stamp                    Ouster
//   time          float32/64     s after the cloud's stamp (may be negative)   Velodyne, LIO-SAM
//   offset_time   uint32         ns after the cloud's stamp                    Livox
//   timestamp     float64        absolute; s, ms, us or ns, whichever lands    Hesai, Livox 2,
//                                nearest the stamp                             RoboSense
//
// Without a time field, times come from the scan geometry (column of an organized cloud, or the
// azimuth swept clockwise from the first point) and the decoder reports that it guessed.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "taiga/core/point_cloud.hpp"

namespace taiga::io {

/// Field data types, with the numbering of sensor_msgs/PointField; the 64-bit integers (which
/// PCD and PLY files may hold) extend it.
enum class FieldType : std::uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
  kInt64 = 9,
  kUint64 = 10,
};

/// Size in bytes of one element of `type`; 0 for a value outside the enumeration.
std::size_t fieldTypeSize(FieldType type);
/// "uint16", "float32", ...
std::string fieldTypeName(FieldType type);

/// Reads one element of `type` at `p` as a double, swapping the bytes when `swap_bytes`.
double unpackValue(const std::uint8_t* p, FieldType type, bool swap_bytes);

/// True when `value` can be stored as `type`: any value (NaN included) for the float types, a
/// whole number within the type's range for the integer types.
bool fitsFieldType(FieldType type, double value);

/// Writes `value` at `p` as one element of `type` in native byte order. Requires
/// fitsFieldType(type, value).
void packValue(std::uint8_t* p, FieldType type, double value);

struct PointField {
  std::string name;
  std::uint32_t offset = 0;  ///< byte offset within a point record
  FieldType type = FieldType::kFloat32;
  std::uint32_t count = 1;   ///< elements (only the first is read)
};

/// Points as packed records, as in sensor_msgs/PointCloud2. `data` is not owned.
struct PackedPoints {
  std::vector<PointField> fields;
  std::uint32_t width = 0;
  std::uint32_t height = 1;  ///< > 1 for organized clouds (rows = beams)
  std::uint32_t point_step = 0;
  std::uint32_t row_step = 0;
  bool is_bigendian = false;
  std::span<const std::uint8_t> data;
};

/// How per-point times were obtained, for the user and for `taiga info`.
enum class PointTimeSource { kRelativeField, kAbsoluteField, kColumnIndex, kAzimuth, kStamp };

/// Whether the times were made up from the geometry (column or azimuth over a nominal sweep).
inline bool timesInvented(PointTimeSource source) {
  return source == PointTimeSource::kColumnIndex || source == PointTimeSource::kAzimuth;
}

struct PointDecodeOptions {
  /// Period of one sweep, s: used only when times must be derived from the geometry.
  double scan_period_s = 0.1;
  /// Field to read per-point time from; empty picks by the table above.
  std::string time_field;
  /// Deskewed upstream (RecordingConfig::deskewed): every point at the stamp, any time field
  /// ignored.
  bool deskewed = false;
};

struct DecodedPoints {
  PointCloud cloud;               ///< valid points only, with absolute times
  std::size_t dropped_invalid = 0;  ///< NaN, infinite or all-zero points (missing returns)
  PointTimeSource time_source = PointTimeSource::kAzimuth;
  std::string time_description;  ///< e.g. "field 't' (uint32, ns after the stamp)"
};

/// Decodes `points` stamped at `stamp_s`. Throws InputError (message without a file name; callers
/// prefix it) when the layout is inconsistent: fields outside the record, data shorter than
/// the declared size, missing or non-float x/y/z, an unknown time field requested.
DecodedPoints decodePackedPoints(const PackedPoints& points, double stamp_s,
                                 const PointDecodeOptions& options = {});

/// A one-line summary of the fields, e.g. "x:float32 y:float32 z:float32 t:uint32 ring:uint16".
std::string describeFields(const std::vector<PointField>& fields);

}  // namespace taiga::io
