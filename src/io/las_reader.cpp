#include "taiga/io/las_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

template <class T>
T get(std::string_view bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

/// Size of the fields each point format starts with (LAS 1.4 R15, tables 7-17).
std::uint16_t minimumRecordLength(std::uint8_t format) {
  constexpr std::uint16_t kLengths[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return kLengths[format];
}

bool hasGpsTime(std::uint8_t format) { return format != 0 && format != 2; }

}  // namespace

LasHeader parseLasHeader(std::string_view bytes, std::uint64_t file_size,
                         std::string_view source_name) {
  constexpr std::size_t kLegacyHeader = 227;
  if (bytes.size() < kLegacyHeader || bytes.substr(0, 4) != "LASF")
    throw InputError(fmt::format("{}: not a LAS file (no 'LASF' signature and {}-byte header)",
                                 source_name, kLegacyHeader));
  LasHeader h;
  const int major = get<std::uint8_t>(bytes, 24);
  h.version_minor = get<std::uint8_t>(bytes, 25);
  if (major != 1 || h.version_minor < 0 || h.version_minor > 4)
    throw InputError(fmt::format("{}: version {}.{}: expected LAS 1.0-1.4", source_name, major,
                                 h.version_minor));
  const auto header_size = get<std::uint16_t>(bytes, 94);
  h.point_data_offset = get<std::uint32_t>(bytes, 96);
  h.point_format = get<std::uint8_t>(bytes, 104) & 0x3f;  // bits 6-7: LAZ compression flags
  h.record_length = get<std::uint16_t>(bytes, 105);
  if (get<std::uint8_t>(bytes, 104) & 0xc0)
    throw InputError(fmt::format("{}: compressed (LAZ) point records are not supported; "
                                 "decompress with laszip or PDAL first",
                                 source_name));
  if (h.point_format > 10)
    throw InputError(fmt::format("{}: point data record format {}: expected 0-10", source_name,
                                 h.point_format));
  if (h.record_length < minimumRecordLength(h.point_format))
    throw InputError(fmt::format("{}: point record length {} B is shorter than format {}'s {} B",
                                 source_name, h.record_length, h.point_format,
                                 minimumRecordLength(h.point_format)));
  h.point_count = get<std::uint32_t>(bytes, 107);
  if (h.version_minor >= 4 && header_size >= 375 && bytes.size() >= 255)
    h.point_count = std::max<std::uint64_t>(h.point_count, get<std::uint64_t>(bytes, 247));
  for (int k = 0; k < 3; ++k) {
    h.scale_m[k] = get<double>(bytes, 131 + 8 * k);
    h.offset_m[k] = get<double>(bytes, 155 + 8 * k);
    h.max_m[k] = get<double>(bytes, 179 + 16 * k);
    h.min_m[k] = get<double>(bytes, 187 + 16 * k);
  }
  if (!(h.scale_m.array() > 0.0).all() || !h.scale_m.allFinite() || !h.offset_m.allFinite())
    throw InputError(fmt::format("{}: scale {} {} {} / offset {} {} {}: expected positive finite "
                                 "scales and finite offsets",
                                 source_name, h.scale_m.x(), h.scale_m.y(), h.scale_m.z(),
                                 h.offset_m.x(), h.offset_m.y(), h.offset_m.z()));
  if (h.point_data_offset < header_size || h.point_data_offset > file_size ||
      h.point_count > (file_size - h.point_data_offset) / h.record_length) {
    throw InputError(fmt::format(
        "{}: point count: {} records of {} B from byte {} do not fit the file's {} bytes "
        "(truncated?)",
        source_name, h.point_count, h.record_length, h.point_data_offset, file_size));
  }
  return h;
}

void decodeLasRecords(const LasHeader& header, std::string_view records, PointCloud& into,
                      std::vector<std::uint16_t>* source_ids) {
  const std::size_t n = records.size() / header.record_length;
  const bool extended = header.point_format >= 6;
  const bool gps = hasGpsTime(header.point_format);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string_view r = records.substr(i * header.record_length, header.record_length);
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k)
      p[k] = header.offset_m[k] + get<std::int32_t>(r, 4 * k) * header.scale_m[k];
    into.positions.push_back(p);
    into.intensities.push_back(get<std::uint16_t>(r, 12));
    into.rings.push_back(get<std::uint8_t>(r, 17));  // user data
    if (gps) into.times_s.push_back(get<double>(r, extended ? 22 : 20));
    if (source_ids) source_ids->push_back(get<std::uint16_t>(r, extended ? 20 : 18));
  }
}

LasReader::LasReader(const std::filesystem::path& path)
    : path_(path), in_(path, std::ios::binary) {
  if (!in_) throw InputError(fmt::format("{}: cannot open", path.string()));
  std::string bytes(375, '\0');
  in_.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in_.gcount()));
  in_.clear();
  header_ = parseLasHeader(bytes, std::filesystem::file_size(path), path.string());
}

void LasReader::read(std::uint64_t first, std::uint64_t count, PointCloud& into,
                     std::vector<std::uint16_t>* source_ids) {
  if (first >= header_.point_count) return;
  count = std::min(count, header_.point_count - first);
  std::string records(count * header_.record_length, '\0');
  in_.seekg(static_cast<std::streamoff>(header_.point_data_offset +
                                        first * header_.record_length));
  in_.read(records.data(), static_cast<std::streamsize>(records.size()));
  if (static_cast<std::uint64_t>(in_.gcount()) != records.size())
    throw InputError(fmt::format("{}: read error at point {}", path_.string(), first));
  decodeLasRecords(header_, records, into, source_ids);
}

PointCloud LasReader::readStrided(std::uint64_t stride, std::vector<std::uint16_t>* source_ids) {
  stride = std::max<std::uint64_t>(stride, 1);
  PointCloud out;
  if (stride == 1) {
    read(0, header_.point_count, out, source_ids);
    return out;
  }
  // Chunks of 64k records, keeping every stride-th: a bounded buffer for any file size.
  constexpr std::uint64_t kChunk = 65536;
  PointCloud chunk;
  std::vector<std::uint16_t> chunk_ids;
  for (std::uint64_t first = 0; first < header_.point_count; first += kChunk) {
    chunk.clear();
    chunk_ids.clear();
    read(first, kChunk, chunk, source_ids ? &chunk_ids : nullptr);
    for (std::uint64_t i = (stride - first % stride) % stride; i < chunk.size(); i += stride) {
      out.positions.push_back(chunk.positions[i]);
      out.intensities.push_back(chunk.intensities[i]);
      out.rings.push_back(chunk.rings[i]);
      if (chunk.hasTimes()) out.times_s.push_back(chunk.times_s[i]);
      if (source_ids) source_ids->push_back(chunk_ids[i]);
    }
  }
  return out;
}

}  // namespace taiga::io
