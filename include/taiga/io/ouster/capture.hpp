#pragma once
// An Ouster capture (pcap + the sensor's metadata JSON) as taiga recording streams: one stream of
// scans and one of IMU samples, each reading the pcap with its own handle.
//
// Opening probes the first datagrams of the capture to find the lidar and IMU ports (the
// metadata's ports when they carry packets of the expected size, else the port that does) and
// checks that the metadata describes the capture: packet sizes must match the metadata's profiles
// and, for non-LEGACY packets, the serial number must match. A mismatch throws InputError naming
// both files. Times are the sensor's timestamps (s, on the clock of its timestamp_mode), the same
// clock for scans and IMU samples; see docs/ouster.md.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "taiga/io/ouster/frame_assembler.hpp"
#include "taiga/io/ouster/imu_packet.hpp"
#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/pcap_reader.hpp"
#include "taiga/io/ouster/sensor_info.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::io::ouster {

struct CaptureOptions {
  DecoderOptions decoder;
  /// Datagrams examined at open to find the ports and check the metadata.
  std::size_t probe_datagrams = 20000;
};

/// What opening learned from the first datagrams.
struct CaptureProbe {
  std::optional<std::uint16_t> lidar_port;  ///< nullopt: no lidar packets in the probed part
  std::optional<std::uint16_t> imu_port;    ///< nullopt: no IMU packets in the probed part
  std::uint64_t datagrams = 0;              ///< datagrams examined
  std::uint64_t lidar_packets = 0;          ///< of the lidar packet size on lidar_port
  std::uint64_t imu_packets = 0;            ///< of the IMU packet size on imu_port
};

/// The payloads of one sensor stream's UDP datagrams: from a capture file (PcapPortSource) or
/// from a socket (live.hpp).
class DatagramSource {
 public:
  virtual ~DatagramSource() = default;
  /// The next payload, valid until the next call; nothing at the end of the stream.
  virtual std::optional<std::span<const std::uint8_t>> next() = 0;
};

/// The datagrams sent to `port` in a capture file, but those of `ignore_size` bytes (when a
/// port carries both streams).
class PcapPortSource final : public DatagramSource {
 public:
  PcapPortSource(const std::filesystem::path& pcap, std::uint16_t port,
                 std::optional<std::size_t> ignore_size = std::nullopt);
  std::optional<std::span<const std::uint8_t>> next() override;

 private:
  PcapReader reader_;
  std::uint16_t port_;
  std::optional<std::size_t> ignore_size_;
};

/// Scans of one lidar packet stream, in the Ouster sensor frame (see frame_assembler.hpp).
class OusterLidarSource final : public StreamSource {
 public:
  /// `name` names the stream in messages, e.g. "drive.pcap (lidar)".
  OusterLidarSource(std::string name, std::unique_ptr<DatagramSource> datagrams,
                    const SensorInfo& info, const DecoderOptions& options = {});
  std::string name() const override { return name_; }
  std::optional<RecordingEvent> next() override;
  /// Like next(), with the frame id and column counts.
  std::optional<AssembledFrame> nextFrame();
  const FrameAssemblerStats& stats() const { return assembler_.stats(); }

 private:
  std::string name_;
  std::unique_ptr<DatagramSource> datagrams_;
  FrameAssembler assembler_;
  bool finished_ = false;
  std::uint64_t delivered_ = 0;
  std::optional<double> last_t_end_s_;
  std::uint64_t out_of_order_ = 0;
};

/// IMU samples of one IMU packet stream, in the IMU frame (see imu_packet.hpp).
class OusterImuSource final : public StreamSource {
 public:
  OusterImuSource(std::string name, std::unique_ptr<DatagramSource> datagrams,
                  const SensorInfo& info, const DecoderOptions& options = {});
  ~OusterImuSource() override;
  std::string name() const override { return name_; }
  std::optional<RecordingEvent> next() override;

  std::uint64_t packets() const { return packets_; }
  std::uint64_t droppedPackets() const { return dropped_packets_; }

 private:
  void reportDrops();

  std::string name_;
  std::unique_ptr<DatagramSource> datagrams_;
  ImuPacketDecoder decoder_;
  std::vector<ImuSample> packet_samples_;
  std::size_t next_sample_ = 0;
  std::optional<double> last_t_s_;
  std::uint64_t packets_ = 0;
  std::uint64_t dropped_packets_ = 0;
  std::uint64_t dropped_samples_ = 0;
  bool warned_ = false;
  bool reported_ = false;
};

struct OusterCapture {
  SensorInfo info;
  CaptureProbe probe;
  std::unique_ptr<OusterLidarSource> lidar;  ///< null when the capture has no lidar packets
  std::unique_ptr<OusterImuSource> imu;      ///< null when the capture has no IMU packets
};

/// Opens both streams of a capture. Throws InputError for unreadable files, metadata that does not
/// describe the capture, or a capture with neither lidar nor IMU packets.
OusterCapture openOusterCaptureStreams(const std::filesystem::path& pcap,
                                       const std::filesystem::path& metadata_json,
                                       const CaptureOptions& options = {});

/// The streams present in the capture, lidar first, for MergedRecording.
std::vector<std::unique_ptr<StreamSource>> openOusterCapture(
    const std::filesystem::path& pcap, const std::filesystem::path& metadata_json,
    const CaptureOptions& options = {});

/// Probes `pcap` as openOusterCaptureStreams does; `metadata_name` names the metadata in
/// messages.
CaptureProbe probeCapture(const std::filesystem::path& pcap, const SensorInfo& info,
                          const std::string& metadata_name, const CaptureOptions& options = {});

}  // namespace taiga::io::ouster
