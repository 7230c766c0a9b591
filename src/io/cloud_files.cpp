#include "taiga/io/cloud_files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "taiga/core/errors.hpp"

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

}  // namespace taiga::io
