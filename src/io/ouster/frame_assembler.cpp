#include "taiga/io/ouster/frame_assembler.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "taiga/core/log.hpp"

namespace taiga::io::ouster {
namespace {

constexpr double kNsToS = 1e-9;
// Warning kinds beyond the PacketStatus values.
constexpr std::size_t kWarnLate = 5;
constexpr std::size_t kWarnBadId = 6;
constexpr std::size_t kWarnDuplicate = 7;

}  // namespace

std::uint64_t FrameAssemblerStats::droppedPackets() const {
  return std::accumulate(dropped.begin(), dropped.end(), std::uint64_t{0});
}

FrameAssembler::FrameAssembler(const SensorInfo& info, const DecoderOptions& options,
                               std::string source_name)
    : info_(info),
      decoder_(info, options),
      geometry_(info),
      source_(source_name.empty() ? info.source : std::move(source_name)),
      received_(static_cast<std::size_t>(info.columns_per_frame), false) {}

void FrameAssembler::warnOnce(std::size_t kind, const std::string& message) {
  if (warned_[kind]) return;
  warned_[kind] = true;
  logger().warn("{}: {} (further cases are counted and reported at the end)", source_, message);
}

PacketStatus FrameAssembler::addPacket(std::span<const std::uint8_t> packet) {
  ++stats_.packets;
  const PacketStatus status = decoder_.decode(packet, packet_);
  if (status != PacketStatus::kOk) {
    const auto kind = static_cast<std::size_t>(status);
    ++stats_.dropped[kind];
    warnOnce(kind, fmt::format("dropped a {}-byte lidar packet: {} (expected {} bytes for {})",
                               packet.size(), describe(status), decoder_.layout().packet_bytes,
                               info_.lidar_profile_name));
    return status;
  }
  if (last_emitted_id_ && packet_.frame_id == *last_emitted_id_) {
    // A straggler of the frame emitted last (reordered or duplicated across the frame boundary):
    // its valid columns come too late, and it must not cut the frame in progress short.
    const auto late = static_cast<std::uint64_t>(std::count_if(
        packet_.columns.begin(), packet_.columns.end(), [](const auto& c) { return c.valid; }));
    stats_.late_columns += late;
    stats_.invalid_columns += packet_.columns.size() - late;
    if (late > 0)
      warnOnce(kWarnLate, fmt::format("dropped {} columns of frame {} that arrived after the "
                                      "frame was emitted",
                                      late, packet_.frame_id));
    return status;
  }
  if (in_frame_ && packet_.frame_id != frame_id_) emitCurrent();
  if (!in_frame_) startFrame(packet_.frame_id);
  for (std::size_t c = 0; c < packet_.columns.size(); ++c) addColumn(c);
  if (received_in_window_ == info_.windowColumns()) emitCurrent();
  return status;
}

void FrameAssembler::startFrame(std::uint32_t frame_id) {
  in_frame_ = true;
  frame_id_ = frame_id;
  std::fill(received_.begin(), received_.end(), false);
  received_in_window_ = 0;
  column_spans_.clear();
  cloud_ = PointCloud();
  cloud_.reserve(static_cast<std::size_t>(info_.windowColumns()) *
                 static_cast<std::size_t>(info_.pixels_per_column));
}

void FrameAssembler::addColumn(std::size_t c) {
  const LidarColumn& column = packet_.columns[c];
  if (!column.valid) {
    ++stats_.invalid_columns;
    return;
  }
  const int id = column.measurement_id;
  if (id >= info_.columns_per_frame) {
    ++stats_.bad_measurement_ids;
    warnOnce(kWarnBadId, fmt::format("dropped a column with measurement id {} (expected < {})", id,
                                     info_.columns_per_frame));
    return;
  }
  if (received_[static_cast<std::size_t>(id)]) {
    ++stats_.duplicate_columns;
    warnOnce(kWarnDuplicate,
             fmt::format("dropped a second copy of column {} of frame {}", id, frame_id_));
    return;
  }
  received_[static_cast<std::size_t>(id)] = true;
  if (info_.inWindow(id)) ++received_in_window_;

  const double t_s = static_cast<double>(column.timestamp_ns) * kNsToS;
  const std::size_t first = cloud_.size();
  const auto pixels = static_cast<std::size_t>(info_.pixels_per_column);
  for (std::size_t row = 0; row < pixels; ++row) {
    const std::uint32_t range_mm = packet_.range_mm[c * pixels + row];
    if (range_mm == 0) continue;  // no return
    cloud_.positions.push_back(geometry_.pointInSensor(static_cast<int>(row), id, range_mm));
    cloud_.times_s.push_back(t_s);
    cloud_.intensities.push_back(static_cast<float>(packet_.reflectivity[c * pixels + row]));
    cloud_.rings.push_back(static_cast<std::uint16_t>(row));
    cloud_.columns.push_back(static_cast<std::uint16_t>(id));
  }
  column_spans_.push_back({t_s, first, cloud_.size() - first});
}

void FrameAssembler::emitCurrent() {
  if (!in_frame_) return;
  in_frame_ = false;
  last_emitted_id_ = frame_id_;
  if (column_spans_.empty()) return;  // only invalid columns: nothing to emit

  // Columns normally arrive in time order; restore it if packets were reordered.
  const auto by_time = [](const ColumnSpan& a, const ColumnSpan& b) { return a.t_s < b.t_s; };
  if (!std::is_sorted(column_spans_.begin(), column_spans_.end(), by_time)) {
    std::stable_sort(column_spans_.begin(), column_spans_.end(), by_time);
    std::vector<std::size_t> order;
    order.reserve(cloud_.size());
    for (const ColumnSpan& span : column_spans_)
      for (std::size_t i = 0; i < span.points; ++i) order.push_back(span.first_point + i);
    cloud_ = cloud_.select(order);
  }

  AssembledFrame frame;
  frame.frame_id = frame_id_;
  frame.columns_received = received_in_window_;
  frame.columns_expected = info_.windowColumns();
  frame.scan.index = next_index_++;
  frame.scan.t_start_s = column_spans_.front().t_s;
  frame.scan.t_end_s = cloud_.empty() ? column_spans_.back().t_s : cloud_.times_s.back();
  frame.scan.cloud_in_lidar = std::move(cloud_);
  cloud_ = PointCloud();
  ++stats_.frames;
  if (!frame.complete()) ++stats_.incomplete_frames;
  ready_.push_back(std::move(frame));
}

void FrameAssembler::finish() {
  emitCurrent();
  const std::uint64_t dropped = stats_.droppedPackets();
  if (dropped > 0 || stats_.late_columns > 0 || stats_.duplicate_columns > 0 ||
      stats_.bad_measurement_ids > 0) {
    logger().warn(
        "{}: dropped {} of {} lidar packets (size {}, packet type {}, CRC {}, other sensor {}), "
        "{} late columns, {} duplicate columns, {} columns with a bad measurement id",
        source_, dropped, stats_.packets, stats_.dropped[1], stats_.dropped[2], stats_.dropped[3],
        stats_.dropped[4], stats_.late_columns, stats_.duplicate_columns,
        stats_.bad_measurement_ids);
  }
}

std::optional<AssembledFrame> FrameAssembler::nextFrame() {
  if (ready_.empty()) return std::nullopt;
  AssembledFrame frame = std::move(ready_.front());
  ready_.pop_front();
  return frame;
}

}  // namespace taiga::io::ouster
