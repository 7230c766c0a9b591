// PCD files as PCL writes them (PCD v0.7 and v0.6 headers): https://pointclouds.org/documentation/
// tutorials/pcd_file_format.html. binary_compressed stores the fields one after the other
// (structure of arrays), compressed with LZF; the other encodings store points one after the other.
#include <fmt/format.h>
#include <lzf.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"

namespace taiga::io {
namespace {

using detail::readWholeFile;
using detail::splitWords;

struct PcdHeader {
  std::vector<std::string> names;
  std::vector<std::uint32_t> sizes, counts;
  std::vector<char> types;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_points = false;
  std::string data;             // ascii | binary | binary_compressed
  std::size_t data_offset = 0;  // first byte after the DATA line
};

FieldType pcdFieldType(char type, std::uint32_t size) {
  if (type == 'F' && size == 4) return FieldType::kFloat32;
  if (type == 'F' && size == 8) return FieldType::kFloat64;
  if (type == 'I' || type == 'U') {
    const bool is_signed = type == 'I';
    switch (size) {
      case 1:
        return is_signed ? FieldType::kInt8 : FieldType::kUint8;
      case 2:
        return is_signed ? FieldType::kInt16 : FieldType::kUint16;
      case 4:
        return is_signed ? FieldType::kInt32 : FieldType::kUint32;
      case 8:
        return is_signed ? FieldType::kInt64 : FieldType::kUint64;
      default:
        break;
    }
  }
  throw InputError(fmt::format("TYPE {} with SIZE {} is not a PCD field type", type, size));
}

std::uint64_t parseCount(const std::string& word, const char* keyword) {
  std::uint64_t value = 0;
  const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec != std::errc() || ptr != word.data() + word.size()) {
    throw InputError(fmt::format("{} expects a whole number, got '{}'", keyword, word));
  }
  return value;
}

PcdHeader parseHeader(const std::string& text) {
  PcdHeader h;
  std::size_t pos = 0;
  int line_number = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const std::vector<std::string> words = splitWords(line);
    if (words.empty() || words[0][0] == '#') continue;
    try {
      const std::string& key = words[0];
      const std::vector<std::string> values(words.begin() + 1, words.end());
      if (key == "VERSION" || key == "VIEWPOINT") continue;
      if (key == "FIELDS" || key == "COLUMNS") {
        h.names = values;
      } else if (key == "SIZE") {
        for (const auto& v : values)
          h.sizes.push_back(static_cast<std::uint32_t>(parseCount(v, "SIZE")));
      } else if (key == "TYPE") {
        for (const auto& v : values) {
          if (v.size() != 1) throw InputError(fmt::format("TYPE expects I, U or F, got '{}'", v));
          h.types.push_back(v[0]);
        }
      } else if (key == "COUNT") {
        for (const auto& v : values)
          h.counts.push_back(static_cast<std::uint32_t>(parseCount(v, "COUNT")));
      } else if (key == "WIDTH" && values.size() == 1) {
        h.width = parseCount(values[0], "WIDTH");
      } else if (key == "HEIGHT" && values.size() == 1) {
        h.height = parseCount(values[0], "HEIGHT");
      } else if (key == "POINTS" && values.size() == 1) {
        h.points = parseCount(values[0], "POINTS");
        h.has_points = true;
      } else if (key == "DATA" && values.size() == 1) {
        h.data = values[0];
        h.data_offset = std::min(pos, text.size());
        return h;
      } else {
        throw InputError(fmt::format("unexpected header line '{}'", line));
      }
    } catch (const InputError& e) {
      throw InputError(fmt::format("header line {}: {}", line_number, e.what()));
    }
  }
  throw InputError("the header ends without a DATA line; not a PCD file or truncated");
}

PackedPoints layoutOf(const PcdHeader& h) {
  if (h.names.empty()) throw InputError("the header has no FIELDS line");
  if (h.sizes.size() != h.names.size() || h.types.size() != h.names.size()) {
    throw InputError(fmt::format("FIELDS lists {} fields but SIZE {} and TYPE {}", h.names.size(),
                                 h.sizes.size(), h.types.size()));
  }
  if (!h.counts.empty() && h.counts.size() != h.names.size()) {
    throw InputError(
        fmt::format("FIELDS lists {} fields but COUNT {}", h.names.size(), h.counts.size()));
  }
  if (h.has_points && h.points != h.width * h.height) {
    throw InputError(
        fmt::format("POINTS {} is not WIDTH {} x HEIGHT {}", h.points, h.width, h.height));
  }
  PackedPoints packed;
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < h.names.size(); ++i) {
    const std::uint32_t count = h.counts.empty() ? 1 : h.counts[i];
    if (count == 0 || count > 1024)
      throw InputError(fmt::format("field '{}' has COUNT {}", h.names[i], count));
    packed.fields.push_back({h.names[i], static_cast<std::uint32_t>(offset),
                             pcdFieldType(h.types[i], h.sizes[i]), count});
    offset += std::uint64_t{h.sizes[i]} * count;
  }
  constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 40;
  if (h.width > UINT32_MAX || h.height > UINT32_MAX ||
      (h.height != 0 && h.width > kMaxPoints / h.height) || offset > 65535) {
    throw InputError(fmt::format("WIDTH {} x HEIGHT {} points of {} bytes is not a plausible size",
                                 h.width, h.height, offset));
  }
  packed.width = static_cast<std::uint32_t>(h.width);
  packed.height = static_cast<std::uint32_t>(h.height);
  packed.point_step = static_cast<std::uint32_t>(offset);
  packed.row_step = packed.width * packed.point_step;
  return packed;
}

std::vector<std::uint8_t> asciiRecords(const std::string& text, std::size_t start,
                                       const PackedPoints& layout) {
  const std::size_t n = std::size_t{layout.width} * layout.height;
  if (n > text.size() - start)
    throw InputError(fmt::format("truncated: {} points announced, the file is too short", n));
  std::vector<std::uint8_t> bytes(n * layout.point_step);
  std::size_t pos = start, point = 0;
  while (point < n && pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::vector<std::string> words =
        splitWords(std::string_view(text).substr(pos, end - pos));
    pos = end + 1;
    if (words.empty()) continue;
    std::uint8_t* record = bytes.data() + point * layout.point_step;
    std::size_t w = 0;
    for (const PointField& f : layout.fields) {
      for (std::uint32_t k = 0; k < f.count; ++k, ++w) {
        if (w >= words.size())
          throw InputError(fmt::format("point {}: {} values, expected more", point, words.size()));
        const double value =
            detail::parseNumber(words[w], fmt::format("point {}, field '{}'", point, f.name));
        if (!fitsFieldType(f.type, value)) {
          throw InputError(fmt::format("point {}, field '{}': {} does not fit {}", point, f.name,
                                       words[w], fieldTypeName(f.type)));
        }
        packValue(record + f.offset + k * fieldTypeSize(f.type), f.type, value);
      }
    }
    ++point;
  }
  if (point < n) throw InputError(fmt::format("truncated: {} points of {} found", point, n));
  return bytes;
}

// binary_compressed: u32 compressed size, u32 uncompressed size, LZF data holding each field's
// values for all points, field after field.
std::vector<std::uint8_t> compressedRecords(const std::string& text, std::size_t start,
                                            const PackedPoints& layout) {
  std::uint32_t sizes[2];
  if (text.size() < start + sizeof sizes) throw InputError("truncated: no compressed data block");
  std::memcpy(sizes, text.data() + start, sizeof sizes);
  const std::size_t n = std::size_t{layout.width} * layout.height;
  const std::size_t expected = n * layout.point_step;
  if (sizes[1] != expected) {
    throw InputError(
        fmt::format("compressed block unpacks to {} bytes, but {} points of {} bytes need {}",
                    sizes[1], n, layout.point_step, expected));
  }
  // LZF encodes at most 264 bytes per 3-byte back reference, so a block cannot unpack to much more
  // than 88 times its size: a larger claim is corruption, not data.
  if (sizes[1] > std::uint64_t{sizes[0]} * 100 + 1024) {
    throw InputError(
        fmt::format("the compressed block claims {} bytes from {}: corrupt", sizes[1], sizes[0]));
  }
  if (text.size() - start - sizeof sizes < sizes[0]) {
    throw InputError(fmt::format("truncated: compressed block of {} bytes, {} present", sizes[0],
                                 text.size() - start - sizeof sizes));
  }
  std::vector<std::uint8_t> fields_major(expected);
  if (expected > 0 && lzf_decompress(text.data() + start + sizeof sizes, sizes[0],
                                     fields_major.data(), sizes[1]) != sizes[1]) {
    throw InputError("the compressed block is corrupt (LZF decompression failed)");
  }
  std::vector<std::uint8_t> bytes(expected);
  std::size_t block = 0;
  for (const PointField& f : layout.fields) {
    const std::size_t size = fieldTypeSize(f.type) * f.count;
    for (std::size_t i = 0; i < n; ++i)
      std::memcpy(bytes.data() + i * layout.point_step + f.offset,
                  fields_major.data() + block + i * size, size);
    block += n * size;
  }
  return bytes;
}

}  // namespace

LoadedPoints parsePcd(const std::string& text) {
  const PcdHeader header = parseHeader(text);
  LoadedPoints loaded;
  loaded.packed = layoutOf(header);
  const std::size_t expected = std::size_t{loaded.packed.row_step} * loaded.packed.height;
  if (header.data == "ascii") {
    loaded.bytes = asciiRecords(text, header.data_offset, loaded.packed);
  } else if (header.data == "binary") {
    if (text.size() - header.data_offset < expected) {
      throw InputError(fmt::format("truncated: {} bytes of point data, {} expected",
                                   text.size() - header.data_offset, expected));
    }
    loaded.bytes.assign(text.begin() + static_cast<std::ptrdiff_t>(header.data_offset),
                        text.begin() + static_cast<std::ptrdiff_t>(header.data_offset + expected));
  } else if (header.data == "binary_compressed") {
    loaded.bytes = compressedRecords(text, header.data_offset, loaded.packed);
  } else {
    throw InputError(
        fmt::format("DATA '{}' is not ascii, binary or binary_compressed", header.data));
  }
  loaded.packed.data = loaded.bytes;
  return loaded;
}

LoadedPoints readPcd(const std::filesystem::path& path) {
  const std::string text = readWholeFile(path);
  try {
    return parsePcd(text);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

}  // namespace taiga::io
