#pragma once
// Byte layouts of Ouster lidar and IMU UDP packets, after the Ouster firmware user manual
// ("Lidar Data Format", "IMU Data Format") and the layout tables of the Ouster SDK:
//
//   lidar packet = [packet header 32 B] + columns_per_packet x column + [packet footer 32 B]
//   column       = column header (16 B LEGACY, 12 B otherwise) + pixels_per_column x pixel
//                  + [column status 4 B, LEGACY only]
//   LEGACY has no packet header or footer; its frame id sits in every column header.
//   The last 8 bytes of the packet footer hold a CRC-64 of all preceding bytes on firmware 3.x;
//   firmware 2.x fills the footer with a constant pattern instead.
//
//   IMU LEGACY            = 48 B: u64 sys ts, u64 accel ts, u64 gyro ts (ns), f32 acc xyz (g),
//                           f32 gyro xyz (deg/s)
//   IMU ACCEL32_GYRO32_NMEA = header 32 B + NMEA block 100 B (u64 ts + 92 B sentence)
//                           + N x 36 B (u64 ts ns, u16 measurement id, u16 status, f32 acc xyz in
//                           m/s^2, f32 gyro xyz in rad/s) + footer 32 B (CRC-64 in the last 8 B)
// All fields are little endian.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "taiga/io/ouster/sensor_info.hpp"

namespace taiga::io::ouster {

/// Whether the CRC-64 trailer of non-LEGACY packets is verified.
enum class CrcCheck {
  kAuto,    ///< verify when the metadata's firmware is 3.0 or later (2.x sends no CRC)
  kAlways,  ///< verify every non-LEGACY packet
  kNever,
};

struct DecoderOptions {
  CrcCheck crc = CrcCheck::kAuto;
  /// Drop non-LEGACY packets whose header names another sensor (serial number) than the
  /// metadata, when the metadata gives one. A different init id (the sensor was re-initialized
  /// since the metadata was saved) is not a reason to drop: the capture opener warns about it.
  bool check_sensor_id = true;
  /// Accept buffers one byte longer than the packet (ouster_ros PacketMsg before 0.10 allocated
  /// packet size + 1); the extra byte is ignored.
  bool allow_trailing_byte = false;
};

/// Outcome of decoding one packet. Anything but kOk means the packet was dropped.
enum class PacketStatus {
  kOk,
  kWrongSize,        ///< not the size the metadata's profile implies
  kWrongPacketType,  ///< header packet type is not lidar (1) / IMU (2)
  kBadCrc,           ///< CRC-64 trailer does not match the bytes
  kOtherSensor,      ///< header serial number differs from the metadata
};
std::string_view describe(PacketStatus status);

struct LidarPacketLayout {
  LidarProfile profile = LidarProfile::kLegacy;
  std::size_t packet_header_bytes = 0;
  std::size_t column_header_bytes = 0;
  std::size_t pixel_bytes = 0;
  std::size_t column_footer_bytes = 0;
  std::size_t packet_footer_bytes = 0;
  std::size_t column_bytes = 0;
  std::size_t packet_bytes = 0;
  int columns_per_packet = 0;
  int pixels_per_column = 0;
  bool dual_return = false;

  /// Throws InputError naming the metadata for profiles this decoder cannot read (OFF, unknown,
  /// FUSA headers) and for packets larger than a UDP datagram.
  static LidarPacketLayout of(const SensorInfo& info);
};

struct ImuPacketLayout {
  ImuProfile profile = ImuProfile::kLegacy;
  std::size_t packet_bytes = 0;
  std::size_t measurements_offset = 0;  ///< first measurement (0 for LEGACY)
  std::size_t measurement_bytes = 0;
  int measurements_per_packet = 1;

  /// Throws InputError naming the metadata for profiles this decoder cannot read.
  static ImuPacketLayout of(const SensorInfo& info);
};

/// True when `info`'s non-LEGACY packets carry a CRC-64 trailer that `check` asks to verify.
bool verifiesCrc(const SensorInfo& info, CrcCheck check);

/// CRC-64/XZ (ECMA-182 polynomial, reflected, init and final xor all ones), the CRC in Ouster
/// packet footers: crc64 of "123456789" is 0x995DC9BBDF1939FA.
std::uint64_t crc64(std::span<const std::uint8_t> bytes);

}  // namespace taiga::io::ouster
