#pragma once
// Decoding one Ouster lidar packet from raw bytes (a pcap datagram's payload or an
// ouster_ros/PacketMsg buffer). Safe for arbitrary bytes: the size is checked against the
// metadata's layout first and every read is bounds-checked; a bad packet gives a PacketStatus,
// never an exception or an out-of-bounds read.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"

namespace taiga::io::ouster {

struct LidarColumn {
  std::uint64_t timestamp_ns = 0;    ///< firing time on the sensor clock (timestamp_mode)
  std::uint16_t measurement_id = 0;  ///< column index in the frame, 0 .. columns_per_frame - 1
  std::uint32_t status = 0;          ///< raw column status (LEGACY: 0xffffffff when valid)
  bool valid = false;                ///< status bit 0: the column was fired (inside the window)
};

/// One decoded packet. Pixel arrays are column-major: index = column * pixels_per_column + row.
struct LidarPacket {
  std::uint32_t frame_id = 0;
  std::uint16_t packet_type = 0;    ///< 1 for lidar; 0 for LEGACY (no packet header)
  std::uint32_t init_id = 0;        ///< 0 for LEGACY
  std::uint64_t serial_number = 0;  ///< 0 for LEGACY
  std::vector<LidarColumn> columns;
  std::vector<std::uint32_t> range_mm;       ///< first (strongest) return; 0 = no return
  std::vector<std::uint16_t> reflectivity;   ///< first return
  std::vector<std::uint16_t> signal;         ///< photons; 0 for profiles without it
  std::vector<std::uint16_t> near_ir;        ///< ambient photons
  std::vector<std::uint32_t> range2_mm;      ///< second return (DUAL profiles), else empty
  std::vector<std::uint16_t> reflectivity2;  ///< second return (DUAL profiles), else empty
};

class LidarPacketDecoder {
 public:
  /// Throws InputError when the metadata's lidar profile cannot be decoded.
  explicit LidarPacketDecoder(const SensorInfo& info, const DecoderOptions& options = {});

  /// Decodes `bytes` into `out` (its buffers are reused). On anything but kOk `out` is
  /// unspecified and the packet must be dropped.
  PacketStatus decode(std::span<const std::uint8_t> bytes, LidarPacket& out) const;

  const LidarPacketLayout& layout() const { return layout_; }
  bool verifiesCrc() const { return verify_crc_; }

 private:
  LidarPacketLayout layout_;
  DecoderOptions options_;
  bool verify_crc_ = false;
  std::optional<std::uint64_t> expected_serial_;
};

}  // namespace taiga::io::ouster
