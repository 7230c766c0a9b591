#include "taiga/io/cloud_files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "taiga/core/errors.hpp"
#include "taiga/io/las_reader.hpp"

namespace taiga::io {

// Moving a vector keeps its buffer, so the span stays valid; re-pointing it keeps that explicit.
LoadedPoints::LoadedPoints(LoadedPoints&& other) noexcept : bytes(std::move(other.bytes)), packed(std::move(other.packed)) {
  packed.data = bytes;
}

LoadedPoints& LoadedPoints::operator=(LoadedPoints&& other) noexcept {
  bytes = std::move(other.bytes);
  packed = std::move(other.packed);
  packed.data = bytes;
  return *this;
}

std::string lowercaseExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return extension;
}

LoadedPoints readCloudFile(const std::filesystem::path& path) {
  const std::string extension = lowercaseExtension(path);
  if (extension == ".pcd") return readPcd(path);
  if (extension == ".ply") return readPly(path);
  throw InputError(fmt::format("{}: unknown point-cloud format '{}'; expected .pcd or .ply", path.string(), extension));
}

DecodedPoints readPointCloudFile(const std::filesystem::path& path, double stamp_s, const PointDecodeOptions& options) {
  const LoadedPoints loaded = readCloudFile(path);
  try {
    return decodePackedPoints(loaded.packed, stamp_s, options);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

PointCloud readAnyCloudFile(const std::filesystem::path& path, std::size_t* skipped) {
  if (skipped) *skipped = 0;
  const std::string ext = lowercaseExtension(path);
  if (ext == ".las") {
    LasReader reader(path);
    PointCloud cloud;
    reader.read(0, reader.pointCount(), cloud);
    return cloud;
  }
  if (ext == ".laz")
    throw InputError(fmt::format(
        "{}: LAZ (compressed LAS) is not read; decompress it first (e.g. `las2las` or `pdal "
        "translate` to .las) or give a PLY or PCD",
        path.string()));
  if (ext == ".ply" || ext == ".pcd") {
    DecodedPoints decoded = readPointCloudFile(path, 0.0);
    if (skipped) *skipped = decoded.dropped_invalid;
    return std::move(decoded.cloud);
  }
  throw InputError(fmt::format("{}: expected a .las, .ply or .pcd point cloud", path.string()));
}

}  // namespace taiga::io
