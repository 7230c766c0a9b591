#pragma once
// Encoding scans and IMU samples as the UDP packets an Ouster sensor sends, and its metadata as
// the JSON it reports: the inverse of lidar_packet.hpp, imu_packet.hpp and sensor_info.hpp, for
// `taiga simulate --pcap` (a capture with ground truth) and for tests of the packet path.
//
// Byte layouts are those of packet_layout.hpp. A scan's points are put back on the sensor's
// column x row grid from their `columns` and `rings` fields, and each point's range is measured
// from its beam origin as the sensor measures it (beam_geometry.hpp, inverted):
//   p_lidar = T_sensor_lidar^-1 p_sensor,
//   range_mm = |p_lidar - o(column)| + |beam origin offset|,  o = (n cos theta_e, n sin theta_e, z)
// so decoding the packets gives the scan's points back to within the range quantum (1 mm, or
// 8 mm for the low-data-rate profiles) when they lie on their beams.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::io::ouster {

struct EncodedPacket {
  double t_s = 0.0;  ///< time of the last column (lidar) or of the sample (IMU), sensor clock
  std::vector<std::uint8_t> bytes;
};

class LidarPacketEncoder {
 public:
  /// Supports LEGACY, RNG19_RFL8_SIG16_NIR16 and RNG15_RFL8_NIR8 (InputError otherwise).
  explicit LidarPacketEncoder(const SensorInfo& info);

  /// The packets of one frame, in firing order. A point needs a column < columns_per_frame and a
  /// ring < pixels_per_column; others throw std::invalid_argument. Column times are the times of
  /// the column's points, or interpolated between scan.t_start_s and scan.t_end_s for columns
  /// without points. A packet whose columns hold no point at all is not sent: that is how a
  /// packet lost on the way shows in the scan it came from.
  std::vector<EncodedPacket> encode(const Scan& scan, std::uint16_t frame_id) const;

 private:
  SensorInfo info_;
  LidarPacketLayout layout_;
  std::vector<double> cos_encoder_, sin_encoder_;
  bool crc_ = false;
};

/// One IMU packet of `info`'s profile holding `samples` (LEGACY: exactly one;
/// ACCEL32_GYRO32_NMEA: at most imu_measurements_per_packet, the rest marked not valid).
EncodedPacket encodeImuPacket(const SensorInfo& info, std::span<const ImuSample> samples);

/// The metadata of `info` in the sensor's current (nested) JSON layout, which parseSensorInfo
/// reads back to the same values.
std::string sensorInfoJson(const SensorInfo& info);

}  // namespace taiga::io::ouster
