#pragma once
// A live Ouster sensor: its lidar and IMU UDP packets received from sockets, decoded by the same
// packet decoders and frame assembler as a capture file (capture.hpp), and delivered as a taiga
// Recording, so `taiga run --live` runs the same SLAM core as on a recording.
//
// A receiver thread drains the sockets as packets arrive (large socket buffers, no processing on
// that thread) into per-stream queues; the recording's streams take them from there. Nothing is
// dropped here: a consumer that falls behind makes the queue grow (LiveStats::max_backlog), and
// the run's feed decides what to drop (pipeline/recording_feed.hpp). Datagrams of neither packet
// size, lost lidar packets (incomplete frames) and the kernel's own drops (a full socket buffer)
// are counted.
//
// The streams end when requestLiveStop() is called (Ctrl-C / SIGTERM in `taiga run --live`),
// when no packet came for idle_timeout_s, or when the LiveCapture is destroyed; the frame in
// progress is then emitted, so the run ends with every output complete.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::io::ouster {

struct LiveOptions {
  std::filesystem::path metadata;  ///< the sensor's metadata JSON
  std::string bind_address = "0.0.0.0";
  std::uint16_t lidar_port = 0;  ///< 0: the metadata's udp_port_lidar, else 7502
  std::uint16_t imu_port = 0;    ///< 0: the metadata's udp_port_imu, else 7503
  double idle_timeout_s = 10.0;  ///< stop after this long without a packet; 0: never
  int socket_buffer_bytes = 64 << 20;
  DecoderOptions decoder;
};

struct LiveStats {
  std::uint64_t lidar_packets = 0;    ///< datagrams of the lidar packet size
  std::uint64_t imu_packets = 0;      ///< datagrams of the IMU packet size
  std::uint64_t other_datagrams = 0;  ///< of neither size: not from this sensor's configuration
  std::uint64_t kernel_drops = 0;     ///< datagrams lost to a full socket buffer
  std::uint64_t frames = 0;           ///< scans assembled
  std::uint64_t incomplete_frames = 0;
  std::uint64_t missing_columns = 0;  ///< in incomplete frames: lost packets x columns_per_packet
  std::uint64_t bad_packets = 0;      ///< of the right size that failed to decode (CRC, ...)
  std::size_t max_backlog = 0;        ///< datagrams received but not yet decoded, at most
  std::string stop_reason;            ///< why the streams ended; empty while they run
};

/// Which stream a datagram belongs to: the live receiver sorts them by size, since a lidar and an
/// IMU packet of the metadata's profiles never have the same size (a port may carry both).
enum class DatagramKind { kLidar, kImu, kOther };
DatagramKind classifyDatagram(std::size_t bytes, std::size_t lidar_bytes, std::size_t imu_bytes);

/// Ends every live capture's streams; async-signal-safe (for SIGINT and SIGTERM handlers).
void requestLiveStop();
bool liveStopRequested();

class LiveCapture {
 public:
  /// Reads the metadata and binds the sockets; InputError naming the file or the address when
  /// either fails. Receiving starts at once.
  explicit LiveCapture(const LiveOptions& options);
  ~LiveCapture();
  LiveCapture(const LiveCapture&) = delete;
  LiveCapture& operator=(const LiveCapture&) = delete;

  const SensorInfo& info() const;
  /// "udp://0.0.0.0:7502+7503", for messages and summaries.
  const std::string& name() const;
  /// The sensor's streams as a recording (call once), with the rig's lidar clock offset and gyro
  /// axes as in openRecording. The recording may outlive this object: its streams then end.
  Recording recording(const RigConfig& rig);
  LiveStats stats() const;
  /// `tap` gets every IMU sample (IMU frame) as its packet arrives, on the receiver thread,
  /// before the recording delivers it in time order: for poses at IMU rate without waiting for
  /// the scan the sample falls into. It must be quick and must not throw.
  void setImuTap(std::function<void(const ImuSample&)> tap);

  struct State;  ///< sockets, receiver thread and queues; shared with the recording's streams

 private:
  std::shared_ptr<State> state_;
};

}  // namespace taiga::io::ouster
