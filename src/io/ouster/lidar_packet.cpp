#include "taiga/io/ouster/lidar_packet.hpp"

#include "byte_reader.hpp"

namespace taiga::io::ouster {
namespace {

using detail::ByteReader;

constexpr std::uint16_t kLidarPacketType = 1;
constexpr std::uint32_t kRange19Mask = 0x7FFFF;
constexpr std::uint32_t kRange20Mask = 0xFFFFF;
constexpr std::uint32_t kRange15Mask = 0x7FFF;
constexpr int kRange15Shift = 3;  // low-data-rate ranges count 8 mm units
constexpr int kNearIr8Shift = 4;  // low-data-rate near-IR keeps the high 8 of 12 bits

struct Pixel {
  std::uint32_t range_mm = 0;
  std::uint16_t reflectivity = 0;
  std::uint16_t signal = 0;
  std::uint16_t near_ir = 0;
  std::uint32_t range2_mm = 0;
  std::uint16_t reflectivity2 = 0;
};

/// Channel data block of one pixel starting at `at` (Ouster firmware user manual, "Lidar Data
/// Format", one table per profile).
Pixel readPixel(ByteReader& r, std::size_t at, LidarProfile profile) {
  Pixel p;
  switch (profile) {
    case LidarProfile::kLegacy:
      p.range_mm = r.le<std::uint32_t>(at) & kRange20Mask;
      p.reflectivity = r.le<std::uint16_t>(at + 4);
      p.signal = r.le<std::uint16_t>(at + 6);
      p.near_ir = r.le<std::uint16_t>(at + 8);
      break;
    case LidarProfile::kRng19Rfl8Sig16Nir16:
    case LidarProfile::kRng19Rfl8Sig16Nir16Zone16:
      p.range_mm = r.le<std::uint32_t>(at) & kRange19Mask;
      p.reflectivity = r.le<std::uint8_t>(at + 4);
      p.signal = r.le<std::uint16_t>(at + 6);
      p.near_ir = r.le<std::uint16_t>(at + 8);
      break;
    case LidarProfile::kRng15Rfl8Nir8:
    case LidarProfile::kRng15Rfl8Nir8Zone16:
    case LidarProfile::kRng15Rfl8Nir8Dual:
      p.range_mm = static_cast<std::uint32_t>(r.le<std::uint16_t>(at) & kRange15Mask)
                   << kRange15Shift;
      p.reflectivity = r.le<std::uint8_t>(at + 2);
      p.near_ir = static_cast<std::uint16_t>(r.le<std::uint8_t>(at + 3) << kNearIr8Shift);
      if (profile == LidarProfile::kRng15Rfl8Nir8Dual) {
        p.range2_mm = static_cast<std::uint32_t>(r.le<std::uint16_t>(at + 4) & kRange15Mask)
                      << kRange15Shift;
        p.reflectivity2 = r.le<std::uint8_t>(at + 6);
      }
      break;
    case LidarProfile::kRng19Rfl8Sig16Nir16Dual:
      p.range_mm = r.le<std::uint32_t>(at) & kRange19Mask;
      p.reflectivity = r.le<std::uint8_t>(at + 3);
      p.range2_mm = r.le<std::uint32_t>(at + 4) & kRange19Mask;
      p.reflectivity2 = r.le<std::uint8_t>(at + 7);
      p.signal = r.le<std::uint16_t>(at + 8);
      p.near_ir = r.le<std::uint16_t>(at + 12);
      break;
    case LidarProfile::kOff:
    case LidarProfile::kOther:
      break;
  }
  return p;
}

}  // namespace

LidarPacketDecoder::LidarPacketDecoder(const SensorInfo& info, const DecoderOptions& options)
    : layout_(LidarPacketLayout::of(info)),
      options_(options),
      verify_crc_(info.lidar_profile != LidarProfile::kLegacy &&
                  ouster::verifiesCrc(info, options.crc)),
      expected_serial_(options.check_sensor_id ? info.serial_number : std::nullopt) {}

PacketStatus LidarPacketDecoder::decode(std::span<const std::uint8_t> bytes,
                                        LidarPacket& out) const {
  const LidarPacketLayout& L = layout_;
  if (options_.allow_trailing_byte && bytes.size() == L.packet_bytes + 1)
    bytes = bytes.first(L.packet_bytes);
  if (bytes.size() != L.packet_bytes) return PacketStatus::kWrongSize;
  ByteReader r(bytes);
  const bool legacy = L.profile == LidarProfile::kLegacy;

  if (legacy) {
    out.packet_type = 0;
    out.init_id = 0;
    out.serial_number = 0;
    out.frame_id = r.le<std::uint16_t>(10);  // in every column header; the first one counts
  } else {
    out.packet_type = r.le<std::uint16_t>(0);
    out.frame_id = r.le<std::uint16_t>(2);
    out.init_id = r.le<std::uint32_t>(4, 3);
    out.serial_number = r.le<std::uint64_t>(7, 5);
    if (out.packet_type != kLidarPacketType) return PacketStatus::kWrongPacketType;
    if (verify_crc_) {
      const std::size_t crc_at = bytes.size() - sizeof(std::uint64_t);
      if (crc64(bytes.first(crc_at)) != r.le<std::uint64_t>(crc_at)) return PacketStatus::kBadCrc;
    }
    if (expected_serial_ && out.serial_number != *expected_serial_)
      return PacketStatus::kOtherSensor;
  }

  const auto columns = static_cast<std::size_t>(L.columns_per_packet);
  const auto pixels = static_cast<std::size_t>(L.pixels_per_column);
  out.columns.resize(columns);
  out.range_mm.resize(columns * pixels);
  out.reflectivity.resize(columns * pixels);
  out.signal.resize(columns * pixels);
  out.near_ir.resize(columns * pixels);
  out.range2_mm.resize(L.dual_return ? columns * pixels : 0);
  out.reflectivity2.resize(L.dual_return ? columns * pixels : 0);

  for (std::size_t c = 0; c < columns; ++c) {
    const std::size_t column_at = L.packet_header_bytes + c * L.column_bytes;
    LidarColumn& column = out.columns[c];
    column.timestamp_ns = r.le<std::uint64_t>(column_at);
    column.measurement_id = r.le<std::uint16_t>(column_at + 8);
    if (legacy) {
      // Legacy status: 32 bits after the pixels, all ones for a valid column.
      column.status = r.le<std::uint32_t>(column_at + L.column_bytes - L.column_footer_bytes);
    } else {
      column.status = r.le<std::uint16_t>(column_at + 10);
    }
    column.valid = (column.status & 1U) != 0;

    for (std::size_t row = 0; row < pixels; ++row) {
      const Pixel p =
          readPixel(r, column_at + L.column_header_bytes + row * L.pixel_bytes, L.profile);
      const std::size_t i = c * pixels + row;
      out.range_mm[i] = p.range_mm;
      out.reflectivity[i] = p.reflectivity;
      out.signal[i] = p.signal;
      out.near_ir[i] = p.near_ir;
      if (L.dual_return) {
        out.range2_mm[i] = p.range2_mm;
        out.reflectivity2[i] = p.reflectivity2;
      }
    }
  }
  // Unreachable after the size check; kept so a layout bug can never read out of bounds.
  return r.failed() ? PacketStatus::kWrongSize : PacketStatus::kOk;
}

}  // namespace taiga::io::ouster
