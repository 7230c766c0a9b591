#include "taiga/io/ouster/packet_layout.hpp"

#include <fmt/format.h>

#include <array>

#include "taiga/core/errors.hpp"

namespace taiga::io::ouster {
namespace {

constexpr std::size_t kUdpMaxPayload = 65507;
constexpr std::size_t kEudpHeaderBytes = 32;
constexpr std::size_t kEudpFooterBytes = 32;
constexpr std::size_t kNmeaBlockBytes = 100;
constexpr std::size_t kImuMeasurementBytes = 36;
constexpr std::size_t kLegacyImuBytes = 48;
// The first firmware whose packet footers carry the CRC-64 (2.x writes a constant pattern).
constexpr FirmwareVersion kFirstCrcFirmware{3, 0, 0};

/// Bytes per pixel of each profile (Ouster firmware user manual, "Lidar Data Format").
std::size_t pixelBytes(LidarProfile profile) {
  switch (profile) {
    case LidarProfile::kLegacy:
    case LidarProfile::kRng19Rfl8Sig16Nir16:
    case LidarProfile::kRng19Rfl8Sig16Nir16Zone16:
      return 12;
    case LidarProfile::kRng15Rfl8Nir8:
      return 4;
    case LidarProfile::kRng15Rfl8Nir8Dual:
    case LidarProfile::kRng15Rfl8Nir8Zone16:
      return 8;
    case LidarProfile::kRng19Rfl8Sig16Nir16Dual:
      return 16;
    case LidarProfile::kOff:
    case LidarProfile::kOther:
      break;
  }
  return 0;
}

// Table-driven CRC-64/XZ (reflected ECMA-182 polynomial 0x42F0E1EBA9EA3693).
constexpr std::array<std::uint64_t, 256> makeCrcTable() {
  constexpr std::uint64_t kReflectedPolynomial = 0xC96C5795D7870F42ULL;
  std::array<std::uint64_t, 256> table{};
  for (std::uint64_t i = 0; i < 256; ++i) {
    std::uint64_t crc = i;
    for (int bit = 0; bit < 8; ++bit)
      crc = (crc & 1) ? (crc >> 1) ^ kReflectedPolynomial : crc >> 1;
    table[i] = crc;
  }
  return table;
}
constexpr std::array<std::uint64_t, 256> kCrcTable = makeCrcTable();

}  // namespace

std::string_view describe(PacketStatus status) {
  switch (status) {
    case PacketStatus::kOk:
      return "ok";
    case PacketStatus::kWrongSize:
      return "wrong size for the metadata's profile";
    case PacketStatus::kWrongPacketType:
      return "wrong packet type in the header";
    case PacketStatus::kBadCrc:
      return "CRC-64 trailer mismatch";
    case PacketStatus::kOtherSensor:
      return "serial number differs from the metadata";
  }
  return "unknown";
}

LidarPacketLayout LidarPacketLayout::of(const SensorInfo& info) {
  const std::size_t pixel = pixelBytes(info.lidar_profile);
  if (pixel == 0) {
    throw InputError(fmt::format(
        "{}: lidar UDP profile '{}' cannot be decoded (supported: LEGACY, RNG19_RFL8_SIG16_NIR16, "
        "RNG15_RFL8_NIR8, RNG19_RFL8_SIG16_NIR16_DUAL, RNG15_RFL8_NIR8_DUAL and the _ZONE16 "
        "variants)",
        info.source, info.lidar_profile_name));
  }
  const bool legacy = info.lidar_profile == LidarProfile::kLegacy;
  if (!legacy && info.header_type != "STANDARD") {
    throw InputError(fmt::format("{}: packet header type '{}' is not supported (only STANDARD)",
                                 info.source, info.header_type));
  }
  LidarPacketLayout layout;
  layout.profile = info.lidar_profile;
  layout.packet_header_bytes = legacy ? 0 : kEudpHeaderBytes;
  layout.column_header_bytes = legacy ? 16 : 12;
  layout.pixel_bytes = pixel;
  layout.column_footer_bytes = legacy ? 4 : 0;
  layout.packet_footer_bytes = legacy ? 0 : kEudpFooterBytes;
  layout.columns_per_packet = info.columns_per_packet;
  layout.pixels_per_column = info.pixels_per_column;
  layout.dual_return = info.lidar_profile == LidarProfile::kRng19Rfl8Sig16Nir16Dual ||
                       info.lidar_profile == LidarProfile::kRng15Rfl8Nir8Dual;
  layout.column_bytes = layout.column_header_bytes +
                        static_cast<std::size_t>(info.pixels_per_column) * pixel +
                        layout.column_footer_bytes;
  layout.packet_bytes = layout.packet_header_bytes +
                        static_cast<std::size_t>(info.columns_per_packet) * layout.column_bytes +
                        layout.packet_footer_bytes;
  if (info.columns_per_packet <= 0 || info.pixels_per_column <= 0 ||
      layout.packet_bytes > kUdpMaxPayload) {
    throw InputError(fmt::format(
        "{}: {} columns of {} pixels per packet make a {}-byte lidar packet; expected at most {} "
        "bytes (one UDP datagram)",
        info.source, info.columns_per_packet, info.pixels_per_column, layout.packet_bytes,
        kUdpMaxPayload));
  }
  return layout;
}

ImuPacketLayout ImuPacketLayout::of(const SensorInfo& info) {
  ImuPacketLayout layout;
  layout.profile = info.imu_profile;
  switch (info.imu_profile) {
    case ImuProfile::kLegacy:
      layout.packet_bytes = kLegacyImuBytes;
      return layout;
    case ImuProfile::kAccel32Gyro32Nmea:
      layout.measurements_per_packet = info.imu_measurements_per_packet;
      layout.measurements_offset = kEudpHeaderBytes + kNmeaBlockBytes;
      layout.measurement_bytes = kImuMeasurementBytes;
      layout.packet_bytes =
          layout.measurements_offset +
          static_cast<std::size_t>(info.imu_measurements_per_packet) * kImuMeasurementBytes +
          kEudpFooterBytes;
      if (layout.packet_bytes > kUdpMaxPayload) {
        throw InputError(fmt::format("{}: {} IMU measurements per packet exceed a UDP datagram",
                                     info.source, info.imu_measurements_per_packet));
      }
      return layout;
    case ImuProfile::kOff:
    case ImuProfile::kOther:
      break;
  }
  throw InputError(fmt::format(
      "{}: IMU UDP profile '{}' cannot be decoded (supported: LEGACY, ACCEL32_GYRO32_NMEA)",
      info.source, info.imu_profile_name));
}

bool verifiesCrc(const SensorInfo& info, CrcCheck check) {
  switch (check) {
    case CrcCheck::kAlways:
      return true;
    case CrcCheck::kNever:
      return false;
    case CrcCheck::kAuto:
      break;
  }
  return info.firmware_version && *info.firmware_version >= kFirstCrcFirmware;
}

std::uint64_t crc64(std::span<const std::uint8_t> bytes) {
  std::uint64_t crc = ~0ULL;
  for (const std::uint8_t byte : bytes) crc = kCrcTable[(crc ^ byte) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

}  // namespace taiga::io::ouster
