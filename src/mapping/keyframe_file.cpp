#include "taiga/mapping/keyframe_file.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

#include "taiga/core/errors.hpp"

namespace taiga::mapping {
namespace {

static_assert(std::endian::native == std::endian::little,
              "keyframe files are little-endian; add byte swapping for a big-endian host");

constexpr std::string_view kMagic = "TAIGAKF1";
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 40;
enum Channel : std::uint32_t { kTimes = 1, kIntensities = 2, kRings = 4, kColumns = 8 };
constexpr std::uint32_t kAllChannels = kTimes | kIntensities | kRings | kColumns;

std::uint32_t channelsOf(const PointCloud& cloud) {
  return (cloud.hasTimes() ? kTimes : 0u) | (cloud.hasIntensities() ? kIntensities : 0u) |
         (cloud.hasRings() ? kRings : 0u) | (cloud.hasColumns() ? kColumns : 0u);
}

/// Bytes per point for the channels, positions included.
std::size_t bytesPerPoint(std::uint32_t channels) {
  return 24 + ((channels & kTimes) ? 8 : 0) + ((channels & kIntensities) ? 4 : 0) +
         ((channels & kRings) ? 2 : 0) + ((channels & kColumns) ? 2 : 0);
}

template <class T>
void put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <class T>
T get(std::string_view bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

template <class T>
std::size_t getArray(std::string_view bytes, std::size_t offset, std::size_t n,
                     std::vector<T>& into) {
  into.resize(n);
  if (n > 0) std::memcpy(into.data(), bytes.data() + offset, n * sizeof(T));
  return offset + n * sizeof(T);
}

KeyframeFileHeader decodeHeader(std::string_view bytes, std::string_view source_name) {
  if (bytes.size() < kHeaderBytes)
    throw InputError(
        fmt::format("{}: not a taiga keyframe file: {} bytes, shorter than the {}-byte "
                    "header (truncated?)",
                    source_name, bytes.size(), kHeaderBytes));
  if (bytes.substr(0, kMagic.size()) != kMagic)
    throw InputError(fmt::format("{}: not a taiga keyframe file: it does not start with '{}'",
                                 source_name, kMagic));
  const auto version = get<std::uint32_t>(bytes, 8);
  if (version != kVersion)
    throw InputError(
        fmt::format("{}: keyframe file version {}, expected {}", source_name, version, kVersion));
  KeyframeFileHeader header;
  header.channels = get<std::uint32_t>(bytes, 12);
  header.id = get<std::uint64_t>(bytes, 16);
  header.t_s = get<double>(bytes, 24);
  header.point_count = get<std::uint64_t>(bytes, 32);
  if ((header.channels & ~kAllChannels) != 0)
    throw InputError(fmt::format("{}: channels: unknown bits in {:#x} (known: 0xf)", source_name,
                                 header.channels));
  return header;
}

/// The file size the header announces, or nothing when it overflows.
std::optional<std::uint64_t> expectedSize(const KeyframeFileHeader& header) {
  const std::uint64_t per_point = bytesPerPoint(header.channels);
  if (header.point_count > (std::numeric_limits<std::uint64_t>::max() - kHeaderBytes) / per_point)
    return std::nullopt;
  return kHeaderBytes + header.point_count * per_point;
}

void checkSize(const KeyframeFileHeader& header, std::uint64_t size, std::string_view source_name) {
  const std::optional<std::uint64_t> expected = expectedSize(header);
  if (!expected || *expected != size) {
    throw InputError(fmt::format(
        "{}: point count: the header announces {} points ({} B per point), the file has {} bytes "
        "(expected {}): truncated or corrupt",
        source_name, header.point_count, bytesPerPoint(header.channels), size,
        expected ? fmt::to_string(*expected) : std::string("more than 2^64")));
  }
}

std::string readAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(fmt::format("{}: cannot open the keyframe file", path.string()));
  // One read of the whole file (a character iterator costs several times as much).
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(fmt::format("{}: cannot read its size", path.string()));
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), size);
  if (in.gcount() != size)
    throw InputError(
        fmt::format("{}: read error ({} of {} bytes)", path.string(), in.gcount(), size));
  return bytes;
}

}  // namespace

namespace {

/// The file's bytes in order: the 40-byte header, then each channel's array whole (positions as
/// x, y, z per point: Eigen's layout of a vector of Vector3d).
struct Encoded {
  std::string header;
  std::vector<std::string_view> arrays;
};

template <class T>
std::string_view bytesOf(const std::vector<T>& values) {
  return {reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)};
}

Encoded encode(std::uint64_t id, double t_s, const PointCloud& cloud_in_body) {
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "positions must be packed x, y, z");
  if (!cloud_in_body.isConsistent())
    throw InputError(fmt::format("keyframe {}: the cloud's channels differ in length", id));
  Encoded out;
  out.header.append(kMagic);
  put(out.header, kVersion);
  put(out.header, channelsOf(cloud_in_body));
  put(out.header, id);
  put(out.header, t_s);
  put(out.header, std::uint64_t{cloud_in_body.size()});
  out.arrays = {bytesOf(cloud_in_body.positions), bytesOf(cloud_in_body.times_s),
                bytesOf(cloud_in_body.intensities), bytesOf(cloud_in_body.rings),
                bytesOf(cloud_in_body.columns)};
  return out;
}

}  // namespace

std::string encodeKeyframe(std::uint64_t id, double t_s, const PointCloud& cloud_in_body) {
  const Encoded encoded = encode(id, t_s, cloud_in_body);
  std::string out = encoded.header;
  for (const std::string_view array : encoded.arrays) out.append(array);
  return out;
}

void writeKeyframeFile(const std::filesystem::path& path, std::uint64_t id, double t_s,
                       const PointCloud& cloud_in_body) {
  // Straight from the cloud's arrays: a copy of the file in RAM first cost a third of the write.
  const Encoded encoded = encode(id, t_s, cloud_in_body);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(fmt::format("{}: cannot write the keyframe file", path.string()));
  out.write(encoded.header.data(), static_cast<std::streamsize>(encoded.header.size()));
  for (const std::string_view array : encoded.arrays)
    out.write(array.data(), static_cast<std::streamsize>(array.size()));
  out.close();
  if (!out) throw writeFailed(path);
}

KeyframeFileContent decodeKeyframe(std::string_view bytes, std::string_view source_name) {
  KeyframeFileContent content;
  content.header = decodeHeader(bytes, source_name);
  checkSize(content.header, bytes.size(), source_name);
  const std::size_t n = content.header.point_count;
  PointCloud& cloud = content.cloud_in_body;
  cloud.positions.resize(n);
  std::size_t offset = kHeaderBytes;
  for (std::size_t i = 0; i < n; ++i, offset += 24) {
    cloud.positions[i] = {get<double>(bytes, offset), get<double>(bytes, offset + 8),
                          get<double>(bytes, offset + 16)};
  }
  const std::uint32_t channels = content.header.channels;
  if (channels & kTimes) offset = getArray(bytes, offset, n, cloud.times_s);
  if (channels & kIntensities) offset = getArray(bytes, offset, n, cloud.intensities);
  if (channels & kRings) offset = getArray(bytes, offset, n, cloud.rings);
  if (channels & kColumns) offset = getArray(bytes, offset, n, cloud.columns);
  return content;
}

KeyframeFileContent readKeyframeFile(const std::filesystem::path& path) {
  return decodeKeyframe(readAll(path), path.string());
}

KeyframeFileHeader readKeyframeHeader(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the keyframe file", path.string()));
  std::string bytes(kHeaderBytes, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(kHeaderBytes));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  const KeyframeFileHeader header = decodeHeader(bytes, path.string());
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec)
    throw InputError(fmt::format("{}: cannot read its size: {}", path.string(), ec.message()));
  checkSize(header, size, path.string());
  return header;
}

}  // namespace taiga::mapping
