#pragma once
// Frame (scan) assembly from Ouster lidar packets, whatever their origin: pcap datagrams, or
// ouster_ros/PacketMsg buffers from a ROS bag.
//
// Columns are collected by frame id. A frame is emitted when
// - every column of the metadata's column window has arrived (complete frame), or
// - a packet of another frame id arrives, or finish() is called (incomplete frame: packet loss,
//   or a capture that starts or ends mid-frame). An incomplete frame still becomes a scan with the
//   columns received; AssembledFrame says how many were expected.
// Invalid columns (status bit 0 clear: outside the azimuth window) carry no data and are skipped.
// Packets that fail to decode (size, type, CRC, other sensor) are dropped and counted; the first
// drop of each kind is logged as a warning, the totals at finish(). Valid columns that arrive for
// a frame already emitted (late or duplicated packets) are dropped and counted likewise.
//
// Points are in the Ouster sensor frame (see beam_geometry.hpp); each point's time is its
// column's timestamp (s), ring = beam row, column = measurement id, intensity = reflectivity
// (first return). Points with range 0 (no return) are dropped. Points are ordered by column time.

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "taiga/io/ouster/beam_geometry.hpp"
#include "taiga/io/ouster/lidar_packet.hpp"
#include "taiga/io/ouster/packet_layout.hpp"
#include "taiga/io/ouster/sensor_info.hpp"
#include "taiga/io/recording.hpp"

namespace taiga::io::ouster {

struct AssembledFrame {
  std::uint32_t frame_id = 0;
  int columns_received = 0;  ///< valid columns inside the column window
  int columns_expected = 0;  ///< SensorInfo::windowColumns()
  Scan scan;
  bool complete() const { return columns_received == columns_expected; }
};

struct FrameAssemblerStats {
  std::uint64_t packets = 0;               ///< offered to addPacket()
  std::array<std::uint64_t, 5> dropped{};  ///< packets dropped, indexed by PacketStatus
  std::uint64_t invalid_columns = 0;       ///< status bit clear (normal outside an azimuth window)
  std::uint64_t bad_measurement_ids = 0;   ///< valid columns with id >= columns_per_frame
  std::uint64_t duplicate_columns = 0;     ///< same measurement id twice in one frame
  std::uint64_t late_columns = 0;          ///< valid columns of a frame already emitted
  std::uint64_t frames = 0;
  std::uint64_t incomplete_frames = 0;

  std::uint64_t droppedPackets() const;
};

class FrameAssembler {
 public:
  /// `source_name` prefixes log messages (default: the metadata's source). Throws InputError when
  /// the metadata's lidar profile cannot be decoded.
  explicit FrameAssembler(const SensorInfo& info, const DecoderOptions& options = {},
                          std::string source_name = "");

  /// Decodes one packet and adds its columns; never throws on packet content. Returns the decode
  /// status (kOk also for a packet whose columns were all dropped as late).
  PacketStatus addPacket(std::span<const std::uint8_t> packet);
  /// End of input: the frame in progress is emitted, and drop totals are logged.
  void finish();

  /// The next emitted frame, oldest first.
  std::optional<AssembledFrame> nextFrame();
  bool hasFrame() const { return !ready_.empty(); }

  const FrameAssemblerStats& stats() const { return stats_; }
  const SensorInfo& info() const { return info_; }
  const LidarPacketDecoder& decoder() const { return decoder_; }

 private:
  struct ColumnSpan {
    double t_s;
    std::size_t first_point;
    std::size_t points;
  };
  void startFrame(std::uint32_t frame_id);
  void addColumn(std::size_t column_in_packet);
  void emitCurrent();
  void warnOnce(std::size_t kind, const std::string& message);

  SensorInfo info_;
  LidarPacketDecoder decoder_;
  BeamGeometry geometry_;
  std::string source_;
  LidarPacket packet_;

  bool in_frame_ = false;
  std::uint32_t frame_id_ = 0;
  std::optional<std::uint32_t> last_emitted_id_;
  std::vector<bool> received_;  ///< per measurement id, in the current frame
  int received_in_window_ = 0;
  std::vector<ColumnSpan> column_spans_;
  PointCloud cloud_;

  std::uint64_t next_index_ = 0;
  std::deque<AssembledFrame> ready_;
  FrameAssemblerStats stats_;
  std::array<bool, 8> warned_{};
};

}  // namespace taiga::io::ouster
