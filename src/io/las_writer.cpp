#include "taiga/io/las_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "LAS is little-endian; so is this writer's machine");

constexpr std::uint16_t kHeaderSize = 375;  // LAS 1.4 public header block
constexpr std::uint16_t kVlrHeaderSize = 54;
constexpr std::uint8_t kPointFormat = 6;
constexpr std::uint16_t kPointRecordSize = 30;    // format 6
constexpr std::uint16_t kExtraBytesRecordId = 4;  // LASF_Spec: Extra Bytes
constexpr std::uint16_t kExtraBytesEntrySize = 192;
constexpr std::uint8_t kExtraFloatType = 9;   // float32
constexpr std::uint16_t kWktRecordId = 2112;  // LASF_Projection: OGC coordinate system WKT
constexpr std::uint16_t kGlobalEncodingWkt = 1 << 4;

class Bytes {
 public:
  template <class T>
  void put(T value) {
    const auto* p = reinterpret_cast<const char*>(&value);
    data_.append(p, sizeof value);
  }
  void putText(const std::string& text, std::size_t width) {  // fixed width, NUL padded
    std::string field = text.substr(0, width);
    field.resize(width, '\0');
    data_ += field;
  }
  void putZeros(std::size_t n) { data_.append(n, '\0'); }
  void reserve(std::size_t n) { data_.reserve(n); }
  const std::string& data() const { return data_; }

 private:
  std::string data_;
};

std::int32_t toScaledInteger(double value_m, double offset_m, double scale_m) {
  const double scaled = std::round((value_m - offset_m) / scale_m);
  if (!(scaled >= std::numeric_limits<std::int32_t>::min() &&
        scaled <= std::numeric_limits<std::int32_t>::max())) {
    throw InputError(fmt::format(
        "coordinate {} m does not fit LAS's 32-bit range at scale {} m around offset {} m", value_m,
        scale_m, offset_m));
  }
  return static_cast<std::int32_t>(scaled);
}

}  // namespace

LasWriter::LasWriter(const std::filesystem::path& path, LasOptions options)
    : path_(path), options_(std::move(options)), out_(path, std::ios::binary) {
  if (!out_) throw InputError(fmt::format("{}: cannot open for writing", path.string()));
  if (!(options_.scale_m > 0.0)) throw std::invalid_argument("LasWriter: scale_m must be positive");
  if (options_.extra_float_name.size() > 31 || options_.extra_float_description.size() > 31)
    throw std::invalid_argument("LasWriter: an extra field's name and description fit 31 bytes");
  if (options_.offset_m) {
    offset_m_ = *options_.offset_m;
    offset_set_ = true;
  }
  min_m_.setConstant(std::numeric_limits<double>::infinity());
  max_m_.setConstant(-std::numeric_limits<double>::infinity());
  writeHeader();  // a placeholder with the right size; close() rewrites it with the totals
}

LasWriter::~LasWriter() {
  try {
    close();
  } catch (...) {  // a destructor cannot report; callers who care call close()
  }
}

void LasWriter::writeHeader() {
  Bytes h;
  h.putText("LASF", 4);
  h.put<std::uint16_t>(0);  // file source ID
  h.put<std::uint16_t>(kGlobalEncodingWkt);
  h.putZeros(16);          // project GUID
  h.put<std::uint8_t>(1);  // version 1.4
  h.put<std::uint8_t>(4);
  h.putText(options_.system_identifier, 32);
  h.putText(options_.generating_software, 32);
  h.put<std::uint16_t>(0);  // creation day and year: unknown, so that equal inputs give equal files
  h.put<std::uint16_t>(0);
  h.put<std::uint16_t>(kHeaderSize);
  const bool has_wkt = !options_.wkt.empty();
  const bool has_extra = !options_.extra_float_name.empty();
  point_data_offset_ =
      kHeaderSize +
      (has_wkt ? kVlrHeaderSize + static_cast<std::uint32_t>(options_.wkt.size()) + 1 : 0) +
      (has_extra ? kVlrHeaderSize + kExtraBytesEntrySize : 0);
  h.put<std::uint32_t>(point_data_offset_);
  h.put<std::uint32_t>((has_wkt ? 1 : 0) + (has_extra ? 1 : 0));  // number of VLRs
  h.put<std::uint8_t>(kPointFormat);
  h.put<std::uint16_t>(kPointRecordSize + (has_extra ? sizeof(float) : 0));
  h.put<std::uint32_t>(0);  // legacy point count: must be 0 for formats 6-10
  h.putZeros(5 * 4);        // legacy points by return
  for (int i = 0; i < 3; ++i) h.put<double>(options_.scale_m);
  for (int i = 0; i < 3; ++i) h.put<double>(offset_m_[i]);
  for (int i = 0; i < 3; ++i) {
    h.put<double>(count_ ? max_m_[i] : 0.0);
    h.put<double>(count_ ? min_m_[i] : 0.0);
  }
  h.put<std::uint64_t>(0);  // start of waveform data
  h.put<std::uint64_t>(0);  // start of first extended VLR
  h.put<std::uint32_t>(0);  // number of extended VLRs
  h.put<std::uint64_t>(count_);
  for (std::uint64_t n : points_by_return_) h.put<std::uint64_t>(n);  // points by return
  if (has_wkt) {
    h.put<std::uint16_t>(0);  // reserved
    h.putText("LASF_Projection", 16);
    h.put<std::uint16_t>(kWktRecordId);
    h.put<std::uint16_t>(static_cast<std::uint16_t>(options_.wkt.size() + 1));
    h.putText("OGC coordinate system WKT", 32);
    h.putText(options_.wkt, options_.wkt.size() + 1);
  }
  if (has_extra) {
    // LAS 1.4 R15, "Extra Bytes": one 192-byte descriptor of a float32 without options.
    h.put<std::uint16_t>(0);  // reserved
    h.putText("LASF_Spec", 16);
    h.put<std::uint16_t>(kExtraBytesRecordId);
    h.put<std::uint16_t>(kExtraBytesEntrySize);
    h.putText("Extra Bytes", 32);
    h.putZeros(2);  // reserved
    h.put<std::uint8_t>(kExtraFloatType);
    h.put<std::uint8_t>(0);  // options: no no-data, min, max, scale or offset
    h.putText(options_.extra_float_name, 32);
    h.putZeros(4 + 8 + 16 + 8 + 16 + 8 + 16 + 8 + 16 + 8 + 16);  // unused .. deprecated5
    h.putText(options_.extra_float_description, 32);
  }
  if (h.data().size() != point_data_offset_)
    throw std::logic_error("LasWriter: header size mismatch");
  out_.seekp(0);
  out_.write(h.data().data(), static_cast<std::streamsize>(h.data().size()));
}

void LasWriter::append(const PointCloud& cloud, std::uint16_t source_id) {
  appendRecords(cloud, {}, source_id);
}

void LasWriter::append(const PointCloud& cloud, std::span<const std::uint8_t> classifications,
                       std::span<const std::uint16_t> source_ids) {
  if (classifications.size() != cloud.size() || source_ids.size() != cloud.size())
    throw std::logic_error("LasWriter::append: one classification and source ID per point");
  appendRecords(cloud, {.classifications = classifications, .source_ids = source_ids}, 0);
}

void LasWriter::append(const PointCloud& cloud, const LasPointFields& fields) {
  const auto fits = [&cloud](std::size_t n) { return n == 0 || n == cloud.size(); };
  if (!fits(fields.classifications.size()) || !fits(fields.source_ids.size()) ||
      !fits(fields.returns.size()) || !fits(fields.extra.size()))
    throw std::logic_error("LasWriter::append: a per-point field not as long as the cloud");
  if (!fields.extra.empty() && options_.extra_float_name.empty())
    throw std::logic_error("LasWriter::append: extra values without LasOptions::extra_float_name");
  for (const auto& [number, of] : fields.returns)
    if (number < 1 || number > of || of > 15)
      throw std::logic_error("LasWriter::append: a return number outside 1..number of returns");
  appendRecords(cloud, fields, 0);
}

void LasWriter::appendRecords(const PointCloud& cloud, const LasPointFields& fields,
                              std::uint16_t source_id) {
  if (closed_) throw std::logic_error("LasWriter::append after close");
  if (cloud.empty()) return;
  if (!offset_set_) {
    // Round the first chunk's minimum down to 1 km: small numbers, and an offset people recognize.
    Eigen::Vector3d lowest = cloud.positions.front();
    for (const Eigen::Vector3d& p : cloud.positions) lowest = lowest.cwiseMin(p);
    offset_m_ = (lowest / 1000.0).array().floor() * 1000.0;
    offset_set_ = true;
    if (!offset_m_.allFinite())
      throw InputError(fmt::format("{}: the points have non-finite coordinates", path_.string()));
  }
  Bytes records;
  records.reserve(cloud.size() *
                  (kPointRecordSize + (options_.extra_float_name.empty() ? 0 : sizeof(float))));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.positions[i];
    Eigen::Vector3d stored;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = toScaledInteger(p[k], offset_m_[k], options_.scale_m);
      records.put<std::int32_t>(v);
      stored[k] = offset_m_[k] + v * options_.scale_m;
    }
    min_m_ = min_m_.cwiseMin(stored);
    max_m_ = max_m_.cwiseMax(stored);
    const float intensity = cloud.hasIntensities() ? cloud.intensities[i] : 0.0f;
    records.put<std::uint16_t>(
        static_cast<std::uint16_t>(std::clamp(std::round(intensity), 0.0f, 65535.0f)));
    // Return number (bits 0-3) and number of returns (bits 4-7): 1 of 1 unless given.
    const std::uint8_t number = fields.returns.empty() ? 1 : fields.returns[i][0];
    records.put<std::uint8_t>(static_cast<std::uint8_t>(
        number | (fields.returns.empty() ? 1 : fields.returns[i][1]) << 4));
    ++points_by_return_[number - 1];
    records.put<std::uint8_t>(0);  // classification flags, scanner channel, scan direction, edge
    records.put<std::uint8_t>(fields.classifications.empty() ? options_.classification
                                                             : fields.classifications[i]);
    records.put<std::uint8_t>(
        cloud.hasRings() ? static_cast<std::uint8_t>(std::min<int>(cloud.rings[i], 255)) : 0);
    records.put<std::int16_t>(0);  // scan angle
    records.put<std::uint16_t>(fields.source_ids.empty() ? source_id : fields.source_ids[i]);
    records.put<double>(cloud.hasTimes() ? cloud.times_s[i] : 0.0);
    if (!options_.extra_float_name.empty())
      records.put<float>(fields.extra.empty() ? 0.0f : fields.extra[i]);
  }
  out_.seekp(0, std::ios::end);
  out_.write(records.data().data(), static_cast<std::streamsize>(records.data().size()));
  if (!out_) throw writeFailed(path_);
  count_ += cloud.size();
}

void LasWriter::close() {
  if (closed_) return;
  closed_ = true;
  writeHeader();
  out_.close();
  if (!out_) throw writeFailed(path_);
}

}  // namespace taiga::io
