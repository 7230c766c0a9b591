#pragma once
// capture.pcap + capture.json of `taiga simulate --pcap PROFILE`: the recording's scans and IMU
// samples as the UDP packets an Ouster sensor would have sent, with its metadata, so the packet
// path (pcap reading, `taiga replay`, `taiga run --live`) is exercised with ground truth. See
// docs/simulator.md, "Ouster captures".
//
// Packets are written in the order of their capture time, the motion time at which the sensor
// sent them (a lidar packet after its last column, an IMU packet at its sample), while their
// timestamps are the sensor clock's, as in the bag. The IMU profile is LEGACY.

#include <filesystem>
#include <vector>

#include "taiga/io/ouster/packet_encoder.hpp"
#include "taiga/io/ouster/pcap_writer.hpp"
#include "taiga/sim/lidar.hpp"

namespace taiga::sim::detail {

/// The metadata of the simulated head: its beam table and frames, `lidar_profile`'s packets.
/// InputError for a head that is not an Ouster (the Velodyne-like models) or a rate that is not
/// a whole number of frames per second.
io::ouster::SensorInfo simulatedSensorInfo(const LidarParams& params, const LidarGeometry& geometry,
                                           const std::string& lidar_profile, std::uint64_t seed);

class OusterCaptureWriter {
 public:
  /// Writes `dir`/capture.json now and opens `dir`/capture.pcap.
  OusterCaptureWriter(const std::filesystem::path& dir, io::ouster::SensorInfo info);
  /// An IMU sample stamped on the sensor clock, sent at `capture_t_s` (s since the Unix epoch).
  void writeImu(const ImuSample& sample, double capture_t_s);
  /// A scan's packets; `capture_minus_stamp_s` turns a column's stamp into the time it fired.
  /// Everything queued up to the scan's last packet is written.
  void writeScan(const io::Scan& scan, std::uint16_t frame_id, double capture_minus_stamp_s);
  void close();

 private:
  struct Queued {
    double capture_t_s;
    std::uint16_t port;
    std::vector<std::uint8_t> bytes;
  };
  void flushUntil(double capture_t_s);

  io::ouster::SensorInfo info_;
  io::ouster::LidarPacketEncoder lidar_;
  io::ouster::PcapWriter pcap_;
  std::vector<Queued> queue_;
};

}  // namespace taiga::sim::detail
