#pragma once
// Decoding one Ouster IMU packet into taiga::ImuSample values in the IMU frame, with acceleration
// in m/s^2 and angular velocity in rad/s. Safe for arbitrary bytes, like LidarPacketDecoder.
//
// Times (s, on the sensor clock of the metadata's timestamp_mode, the clock of the lidar column
// timestamps):
// - LEGACY: the gyroscope read time. The packet holds three times: the system time (always the
//   time since boot, whatever timestamp_mode says), the accelerometer read time and the gyroscope
//   read time (both on the timestamp_mode clock). The gyroscope time is taken because it shares
//   the lidar's clock, because rotation dominates motion compensation, and because ouster-ros
//   stamps its Imu messages with it, so pcaps and ouster-ros bags give the same times. The
//   accelerometer is read about 0.22 ms earlier; that offset is not corrected.
// - ACCEL32_GYRO32_NMEA: each measurement's own timestamp; measurements whose status bit 0 is
//   clear are skipped. The NMEA block is not decoded.

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"

namespace taiga::io::ouster {

/// Standard gravity, for LEGACY accelerations reported in g.
inline constexpr double kStandardGravity_mps2 = 9.80665;

class ImuPacketDecoder {
 public:
  /// Throws InputError when the metadata's IMU profile cannot be decoded.
  explicit ImuPacketDecoder(const SensorInfo& info, const DecoderOptions& options = {});

  /// Replaces `samples` with the packet's valid samples in time order. On anything but kOk
  /// `samples` is empty and the packet must be dropped. Samples with non-finite values or a zero
  /// time are skipped (counted in `skipped_samples` when given).
  PacketStatus decode(std::span<const std::uint8_t> bytes, std::vector<ImuSample>& samples,
                      int* skipped_samples = nullptr) const;

  const ImuPacketLayout& layout() const { return layout_; }
  bool verifiesCrc() const { return verify_crc_; }

 private:
  ImuPacketLayout layout_;
  DecoderOptions options_;
  bool verify_crc_ = false;
  std::optional<std::uint64_t> expected_serial_;
};

}  // namespace taiga::io::ouster
