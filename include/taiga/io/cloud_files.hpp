#pragma once
// Point-cloud files: PCD (ascii, binary, binary_compressed) and PLY (ascii, binary little and big
// endian) in; PLY out. Reading turns a file into packed points (point_fields.hpp), so files and
// ROS messages share one decoder and one set of time conventions.
//
// Errors are InputErrors naming the file and, where there is one, the header line or field.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/io/point_fields.hpp"

namespace taiga::io {

/// Packed points that own their bytes (`packed.data` views `bytes`).
struct LoadedPoints {
  std::vector<std::uint8_t> bytes;
  PackedPoints packed;

  LoadedPoints() = default;
  LoadedPoints(LoadedPoints&& other) noexcept;
  LoadedPoints& operator=(LoadedPoints&& other) noexcept;
};

LoadedPoints readPcd(const std::filesystem::path& path);
LoadedPoints readPly(const std::filesystem::path& path);
/// The same from the bytes of a file (for tests and fuzzing); errors carry no file name.
LoadedPoints parsePcd(const std::string& bytes);
LoadedPoints parsePly(const std::string& bytes);
/// PCD or PLY by extension (.pcd, .ply, case-insensitive).
LoadedPoints readCloudFile(const std::filesystem::path& path);
/// The file's extension in lower case, with its dot (".ply"; "" when none): how files are told apart.
std::string lowercaseExtension(const std::filesystem::path& path);

/// Reads and decodes a PCD or PLY file; `stamp_s` is the time relative per-point times count from.
DecodedPoints readPointCloudFile(const std::filesystem::path& path, double stamp_s,
                                 const PointDecodeOptions& options = {});

/// Any cloud file a user has: LAS (las_reader.hpp), PLY or PCD, by extension; LAZ is refused with
/// advice. Points with NaN, infinite or zero coordinates (PLY, PCD) are skipped and counted in
/// `skipped`. InputError naming the file.
PointCloud readAnyCloudFile(const std::filesystem::path& path, std::size_t* skipped = nullptr);

/// Writes binary little-endian PLY with x, y, z as float64 (so georeferenced coordinates keep
/// full precision) and whichever of time (float64, s), intensity (float32), ring and column
/// (uint16) the cloud carries. CloudCompare, MeshLab and lidR read it.
void writePly(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace taiga::io
