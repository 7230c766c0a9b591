// PLY files (http://paulbourke.net/dataformats/ply/): the vertex element becomes packed points;
// other elements (faces, ...) are skipped. CloudCompare prefixes its scalar fields with "scalar_",
// which is removed so that "scalar_intensity" is recognized as intensity.
#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <functional>
#include <optional>

#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"

namespace taiga::io {
namespace {

using detail::splitWords;

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  FieldType type = FieldType::kFloat32;
  std::optional<FieldType> list_count_type;  // set for list properties
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;
};

FieldType plyType(const std::string& name) {
  static const std::pair<const char*, FieldType> kTypes[] = {
      {"char", FieldType::kInt8},      {"int8", FieldType::kInt8},
      {"uchar", FieldType::kUint8},    {"uint8", FieldType::kUint8},
      {"short", FieldType::kInt16},    {"int16", FieldType::kInt16},
      {"ushort", FieldType::kUint16},  {"uint16", FieldType::kUint16},
      {"int", FieldType::kInt32},      {"int32", FieldType::kInt32},
      {"uint", FieldType::kUint32},    {"uint32", FieldType::kUint32},
      {"float", FieldType::kFloat32},  {"float32", FieldType::kFloat32},
      {"double", FieldType::kFloat64}, {"float64", FieldType::kFloat64}};
  for (const auto& [text, type] : kTypes) {
    if (name == text) return type;
  }
  throw InputError(fmt::format("'{}' is not a PLY property type", name));
}

std::string plyTypeName(FieldType type) {
  switch (type) {
    case FieldType::kInt8:
      return "char";
    case FieldType::kUint8:
      return "uchar";
    case FieldType::kInt16:
      return "short";
    case FieldType::kUint16:
      return "ushort";
    case FieldType::kInt32:
      return "int";
    case FieldType::kUint32:
      return "uint";
    case FieldType::kFloat64:
      return "double";
    default:
      return "float";
  }
}

PlyHeader parseHeader(const std::string& text) {
  if (!text.starts_with("ply\n") && !text.starts_with("ply\r\n"))
    throw InputError("does not start with 'ply': not a PLY file");
  PlyHeader h;
  std::size_t pos = 0;
  int line_number = 0;
  bool has_format = false;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::vector<std::string> w = splitWords(std::string_view(text).substr(pos, end - pos));
    pos = end + 1;
    ++line_number;
    if (w.empty() || w[0] == "ply" || w[0] == "comment" || w[0] == "obj_info") continue;
    try {
      if (w[0] == "format" && w.size() == 3) {
        if (w[1] == "ascii")
          h.format = PlyFormat::kAscii;
        else if (w[1] == "binary_little_endian")
          h.format = PlyFormat::kBinaryLittleEndian;
        else if (w[1] == "binary_big_endian")
          h.format = PlyFormat::kBinaryBigEndian;
        else
          throw InputError(fmt::format("unknown format '{}'", w[1]));
        has_format = true;
      } else if (w[0] == "element" && w.size() == 3) {
        const double count = detail::parseNumber(w[2], "element count");
        if (!(count >= 0 && count < 1e12 && count == std::trunc(count)))
          throw InputError(fmt::format("element count '{}'", w[2]));
        h.elements.push_back({w[1], static_cast<std::uint64_t>(count), {}});
      } else if (w[0] == "property" && !h.elements.empty() && w.size() == 3) {
        h.elements.back().properties.push_back({w[2], plyType(w[1]), std::nullopt});
      } else if (w[0] == "property" && !h.elements.empty() && w.size() == 5 && w[1] == "list") {
        h.elements.back().properties.push_back({w[4], plyType(w[3]), plyType(w[2])});
      } else if (w[0] == "end_header") {
        if (!has_format) throw InputError("no format line before end_header");
        h.data_offset = std::min(pos, text.size());
        return h;
      } else {
        throw InputError("unexpected line");
      }
    } catch (const InputError& e) {
      throw InputError(fmt::format("header line {}: {}", line_number, e.what()));
    }
  }
  throw InputError("the header has no end_header line; truncated?");
}

// Reads one binary element value and advances `pos`; throws at the end of the data.
double readBinary(const std::string& text, std::size_t& pos, FieldType type, bool big_endian) {
  const std::size_t size = fieldTypeSize(type);
  if (text.size() - pos < size) throw InputError("truncated: the data ends inside an element");
  const double value = unpackValue(reinterpret_cast<const std::uint8_t*>(text.data()) + pos, type,
                                   big_endian != (std::endian::native == std::endian::big));
  pos += size;
  return value;
}

// Skips an element that is not the vertices (faces, edges, ...).
void skipElement(const std::string& text, std::size_t& pos, const PlyElement& element,
                 PlyFormat format) {
  // A binary element without properties takes no bytes: nothing to skip, however many it claims
  // (a fuzzed header claimed 3e10, which took minutes one by one).
  if (format != PlyFormat::kAscii && element.properties.empty()) return;
  for (std::uint64_t i = 0; i < element.count; ++i) {
    if (format == PlyFormat::kAscii) {
      const std::size_t end = text.find('\n', pos);
      if (end == std::string::npos)
        throw InputError(fmt::format("truncated inside element '{}'", element.name));
      pos = end + 1;
      continue;
    }
    const bool big = format == PlyFormat::kBinaryBigEndian;
    for (const PlyProperty& p : element.properties) {
      const double n = p.list_count_type ? readBinary(text, pos, *p.list_count_type, big) : 1.0;
      if (!(n >= 0 && n <= 1e6))
        throw InputError(fmt::format("element '{}': list length {}", element.name, n));
      const std::size_t bytes = static_cast<std::size_t>(n) * fieldTypeSize(p.type);
      if (text.size() - pos < bytes) throw InputError("truncated: the data ends inside an element");
      pos += bytes;
    }
  }
}

}  // namespace

LoadedPoints parsePly(const std::string& text) {
  const PlyHeader h = parseHeader(text);
  std::size_t pos = h.data_offset;
  for (const PlyElement& element : h.elements) {
    if (element.name != "vertex") {
      skipElement(text, pos, element, h.format);
      continue;
    }
    LoadedPoints loaded;
    PackedPoints& packed = loaded.packed;
    for (const PlyProperty& p : element.properties) {
      if (p.list_count_type)
        throw InputError(fmt::format("vertex property '{}' is a list; expected scalars", p.name));
      const std::string name = p.name.starts_with("scalar_") ? p.name.substr(7) : p.name;
      packed.fields.push_back({name, packed.point_step, p.type, 1});
      packed.point_step += static_cast<std::uint32_t>(fieldTypeSize(p.type));
    }
    if (element.count > UINT32_MAX)
      throw InputError(fmt::format("{} vertices is too many", element.count));
    packed.width = static_cast<std::uint32_t>(element.count);
    packed.height = 1;
    packed.row_step = packed.width * packed.point_step;
    const std::size_t bytes = std::size_t{packed.row_step};
    if (h.format != PlyFormat::kAscii) {
      if (text.size() - pos < bytes) {
        throw InputError(fmt::format("truncated: {} vertices need {} bytes, {} present",
                                     element.count, bytes, text.size() - pos));
      }
      loaded.bytes.assign(text.begin() + static_cast<std::ptrdiff_t>(pos),
                          text.begin() + static_cast<std::ptrdiff_t>(pos + bytes));
      packed.is_bigendian = h.format == PlyFormat::kBinaryBigEndian;
    } else {
      if (element.count > text.size() - pos)
        throw InputError("truncated: fewer lines than vertices");
      loaded.bytes.resize(bytes);
      for (std::uint64_t i = 0; i < element.count; ++i) {
        if (pos >= text.size())
          throw InputError(fmt::format("truncated: {} of {} vertices", i, element.count));
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        const std::vector<std::string> w =
            splitWords(std::string_view(text).substr(pos, end - pos));
        pos = end + 1;
        if (w.size() < packed.fields.size())
          throw InputError(
              fmt::format("vertex {}: {} values, expected {}", i, w.size(), packed.fields.size()));
        for (std::size_t k = 0; k < packed.fields.size(); ++k) {
          const PointField& f = packed.fields[k];
          const double value =
              detail::parseNumber(w[k], fmt::format("vertex {}, property '{}'", i, f.name));
          if (!fitsFieldType(f.type, value))
            throw InputError(fmt::format("vertex {}, property '{}': {} does not fit {}", i, f.name,
                                         w[k], plyTypeName(f.type)));
          packValue(loaded.bytes.data() + i * packed.point_step + f.offset, f.type, value);
        }
      }
    }
    packed.data = loaded.bytes;
    return loaded;
  }
  throw InputError("no vertex element");
}

LoadedPoints readPly(const std::filesystem::path& path) {
  const std::string text = detail::readWholeFile(path);
  try {
    return parsePly(text);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

void writePly(const std::filesystem::path& path, const PointCloud& cloud) {
  struct Column {
    const char* name;
    FieldType type;
    std::function<double(std::size_t)> value;
  };
  std::vector<Column> columns{
      {"x", FieldType::kFloat64, [&](std::size_t i) { return cloud.positions[i].x(); }},
      {"y", FieldType::kFloat64, [&](std::size_t i) { return cloud.positions[i].y(); }},
      {"z", FieldType::kFloat64, [&](std::size_t i) { return cloud.positions[i].z(); }}};
  if (cloud.hasTimes())
    columns.push_back(
        {"time", FieldType::kFloat64, [&](std::size_t i) { return cloud.times_s[i]; }});
  if (cloud.hasIntensities())
    columns.push_back(
        {"intensity", FieldType::kFloat32, [&](std::size_t i) { return cloud.intensities[i]; }});
  if (cloud.hasRings())
    columns.push_back({"ring", FieldType::kUint16, [&](std::size_t i) { return cloud.rings[i]; }});
  if (cloud.hasColumns())
    columns.push_back(
        {"column", FieldType::kUint16, [&](std::size_t i) { return cloud.columns[i]; }});

  std::string header = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment written by taiga\nelement vertex {}\n",
      cloud.size());
  std::size_t record_size = 0;
  for (const Column& c : columns) {
    header += fmt::format("property {} {}\n", plyTypeName(c.type), c.name);
    record_size += fieldTypeSize(c.type);
  }
  header += "end_header\n";
  std::vector<std::uint8_t> data(record_size * cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint8_t* p = data.data() + i * record_size;
    for (const Column& c : columns) {
      packValue(p, c.type, c.value(i));
      p += fieldTypeSize(c.type);
    }
  }
  static_assert(std::endian::native == std::endian::little,
                "PLY output assumes a little-endian machine");
  std::ofstream out(path, std::ios::binary);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
}

}  // namespace taiga::io
