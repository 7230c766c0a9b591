// The lidar and IMU streams of an Ouster capture.

#include <fmt/format.h>

#include "taiga/core/log.hpp"
#include "taiga/io/ouster/capture.hpp"

namespace taiga::io::ouster {

PcapPortSource::PcapPortSource(const std::filesystem::path& pcap, std::uint16_t port,
                               std::optional<std::size_t> ignore_size)
    : reader_(pcap), port_(port), ignore_size_(ignore_size) {}

std::optional<std::span<const std::uint8_t>> PcapPortSource::next() {
  while (const std::optional<UdpDatagram> datagram = reader_.next()) {
    if (datagram->destination_port != port_) continue;
    if (ignore_size_ && datagram->payload.size() == *ignore_size_) continue;
    return datagram->payload;
  }
  return std::nullopt;
}

OusterLidarSource::OusterLidarSource(std::string name, std::unique_ptr<DatagramSource> datagrams,
                                     const SensorInfo& info, const DecoderOptions& options)
    : name_(std::move(name)), datagrams_(std::move(datagrams)), assembler_(info, options, name_) {}

std::optional<AssembledFrame> OusterLidarSource::nextFrame() {
  while (true) {
    if (std::optional<AssembledFrame> frame = assembler_.nextFrame()) {
      // The stream's contract is non-decreasing event times; a sensor clock that jumps back
      // (re-initialization inside the capture) cannot honour it.
      if (last_t_end_s_ && frame->scan.t_end_s < *last_t_end_s_) {
        if (out_of_order_++ == 0) {
          logger().warn(
              "{}: dropped frame {} whose time {:.6f} s is before the previous scan's "
              "{:.6f} s (the sensor clock went back)",
              name_, frame->frame_id, frame->scan.t_end_s, *last_t_end_s_);
        }
        continue;
      }
      last_t_end_s_ = frame->scan.t_end_s;
      frame->scan.index = delivered_++;
      return frame;
    }
    if (finished_) return std::nullopt;
    const std::optional<std::span<const std::uint8_t>> payload = datagrams_->next();
    if (!payload) {
      finished_ = true;
      assembler_.finish();
      if (out_of_order_ > 1)
        logger().warn("{}: dropped {} frames whose time went back", name_, out_of_order_);
      continue;
    }
    assembler_.addPacket(*payload);
  }
}

std::optional<RecordingEvent> OusterLidarSource::next() {
  std::optional<AssembledFrame> frame = nextFrame();
  if (!frame) return std::nullopt;
  return RecordingEvent(std::move(frame->scan));
}

OusterImuSource::OusterImuSource(std::string name, std::unique_ptr<DatagramSource> datagrams,
                                 const SensorInfo& info, const DecoderOptions& options)
    : name_(std::move(name)), datagrams_(std::move(datagrams)), decoder_(info, options) {}

OusterImuSource::~OusterImuSource() { reportDrops(); }

void OusterImuSource::reportDrops() {
  if (reported_ || (dropped_packets_ == 0 && dropped_samples_ == 0)) return;
  reported_ = true;
  logger().warn(
      "{}: dropped {} of {} IMU packets and {} samples (unusable values or time going "
      "back)",
      name_, dropped_packets_, packets_, dropped_samples_);
}

std::optional<RecordingEvent> OusterImuSource::next() {
  while (true) {
    while (next_sample_ < packet_samples_.size()) {
      const ImuSample& sample = packet_samples_[next_sample_++];
      if (last_t_s_ && sample.t_s < *last_t_s_) {
        ++dropped_samples_;
        continue;
      }
      last_t_s_ = sample.t_s;
      return RecordingEvent(sample);
    }
    const std::optional<std::span<const std::uint8_t>> payload = datagrams_->next();
    if (!payload) {
      reportDrops();
      return std::nullopt;
    }
    ++packets_;
    int skipped = 0;
    next_sample_ = 0;
    const PacketStatus status = decoder_.decode(*payload, packet_samples_, &skipped);
    dropped_samples_ += static_cast<std::uint64_t>(skipped);
    if (status != PacketStatus::kOk) {
      ++dropped_packets_;
      if (!warned_) {
        warned_ = true;
        logger().warn(
            "{}: dropped a {}-byte IMU packet: {} (expected {} bytes for {}; further "
            "drops are counted and reported at the end)",
            name_, payload->size(), describe(status), decoder_.layout().packet_bytes,
            profileName(decoder_.layout().profile));
      }
    }
  }
}

}  // namespace taiga::io::ouster
