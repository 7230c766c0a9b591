#pragma once
// One keyframe's full-resolution deskewed scan on disk (keyframes/NNNNNN.tkf), lossless:
//
//   offset  size  field
//   0       8     magic "TAIGAKF1"
//   8       4     uint32 version (1)
//   12      4     uint32 channels: bit 0 times_s, bit 1 intensities, bit 2 rings, bit 3 columns
//   16      8     uint64 keyframe id
//   24      8     float64 t_s, the keyframe's time (the scan's end, recording clock)
//   32      8     uint64 n, the number of points
//   40      ...   n x 3 float64 positions in the body frame (x, y, z per point), m
//                 then, for each channel present, in bit order: n float64 times_s (absolute),
//                 n float32 intensities, n uint16 rings, n uint16 columns
//
// Little-endian throughout (the host order on x86-64 and arm64; a big-endian host is refused at
// compile time). The file size must be exactly what the header announces, so a truncated or
// padded file is an error. A cloud reads back bit for bit: 24 B per point for positions, + 8 for
// times, + 4 for intensities, + 2 + 2 for rings and columns (40 B for an Ouster point).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "taiga/core/point_cloud.hpp"

namespace taiga::mapping {

struct KeyframeFileHeader {
  std::uint64_t id = 0;
  double t_s = 0.0;
  std::uint64_t point_count = 0;
  std::uint32_t channels = 0;
};

struct KeyframeFileContent {
  KeyframeFileHeader header;
  PointCloud cloud_in_body;
};

/// Writes the cloud (consistent channels) as a keyframe file; InputError when it cannot.
void writeKeyframeFile(const std::filesystem::path& path, std::uint64_t id, double t_s,
                       const PointCloud& cloud_in_body);
/// The bytes writeKeyframeFile() writes.
std::string encodeKeyframe(std::uint64_t id, double t_s, const PointCloud& cloud_in_body);

/// Reads a keyframe file back; InputError naming the file and what is wrong (magic, version,
/// channels, size) otherwise.
KeyframeFileContent readKeyframeFile(const std::filesystem::path& path);
/// Only the header (for reopening a store without reading every point); the file size is checked.
KeyframeFileHeader readKeyframeHeader(const std::filesystem::path& path);
/// The same from bytes; `source_name` stands for the file in messages (tests, fuzzing).
KeyframeFileContent decodeKeyframe(std::string_view bytes, std::string_view source_name);

}  // namespace taiga::mapping
