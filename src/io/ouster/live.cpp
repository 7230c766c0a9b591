#include "taiga/io/ouster/live.hpp"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "taiga/core/log.hpp"
#include "taiga/io/ouster/capture.hpp"
#include "taiga/io/ouster/imu_packet.hpp"
#include "taiga/io/udp_socket.hpp"

namespace taiga::io::ouster {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::uint16_t kDefaultLidarPort = 7502;
constexpr std::uint16_t kDefaultImuPort = 7503;
constexpr auto kPollInterval = std::chrono::milliseconds(100);  // how soon a stop is noticed
enum Stream : std::size_t { kLidar = 0, kImu = 1 };

std::atomic<bool> g_stop_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free,
              "a signal handler may only touch lock-free atomics");

}  // namespace

DatagramKind classifyDatagram(std::size_t bytes, std::size_t lidar_bytes, std::size_t imu_bytes) {
  if (bytes == 0) return DatagramKind::kOther;  // also when a stream is off (its size 0)
  if (bytes == lidar_bytes) return DatagramKind::kLidar;
  if (bytes == imu_bytes) return DatagramKind::kImu;
  return DatagramKind::kOther;
}

void requestLiveStop() { g_stop_requested.store(true); }
bool liveStopRequested() { return g_stop_requested.load(); }

struct LiveCapture::State {
  LiveOptions options;
  SensorInfo info;
  std::string name;
  std::size_t lidar_bytes = 0, imu_bytes = 0;
  std::vector<UdpSocket> sockets;  // one per distinct port

  mutable std::mutex mutex;
  std::condition_variable arrived;
  std::array<std::deque<std::vector<std::uint8_t>>, 2> queues;
  bool closed = false;
  bool stopping = false;  // the LiveCapture is going away
  LiveStats stats;
  std::thread receiver;

  std::mutex tap_mutex;
  std::function<void(const ImuSample&)> imu_tap;
  std::optional<ImuPacketDecoder> tap_decoder;
  std::vector<ImuSample> tap_samples;

  void receive();
  /// Hands an IMU packet's samples to the tap, on the receiver thread, as it arrives.
  void tapImu(std::span<const std::uint8_t> packet);
  void close(std::string reason);
  /// The next datagram of `stream` into `buffer`; false at the end.
  bool pop(Stream stream, std::vector<std::uint8_t>& buffer);
};

void LiveCapture::State::close(std::string reason) {
  {
    std::lock_guard lock(mutex);
    if (closed) return;
    closed = true;
    stats.stop_reason = std::move(reason);
  }
  arrived.notify_all();
}

void LiveCapture::State::receive() {
  std::vector<const UdpSocket*> polled;
  for (const UdpSocket& s : sockets) polled.push_back(&s);
  Clock::time_point last_packet = Clock::now();
  std::vector<std::uint8_t> buffer;
  bool warned_other = false;
  while (true) {
    {
      std::lock_guard lock(mutex);
      if (stopping) break;
    }
    if (liveStopRequested()) {
      close("stop requested (a signal)");
      return;
    }
    const double idle_s = std::chrono::duration<double>(Clock::now() - last_packet).count();
    if (options.idle_timeout_s > 0.0 && idle_s > options.idle_timeout_s) {
      logger().warn("{}: no packet for {:.0f} s (live.idle_timeout_s): the sensor stopped sending",
                    name, options.idle_timeout_s);
      close(fmt::format("no packet for {:.0f} s", options.idle_timeout_s));
      return;
    }
    for (const std::size_t i : waitReadable(polled, kPollInterval)) {
      UdpSocket& socket = sockets[i];
      while (socket.receive(buffer)) {  // drain: the kernel buffer is the only other queue
        last_packet = Clock::now();
        const DatagramKind kind = classifyDatagram(buffer.size(), lidar_bytes, imu_bytes);
        if (kind == DatagramKind::kImu) tapImu(buffer);
        const Stream stream = kind == DatagramKind::kLidar ? kLidar : kImu;
        std::lock_guard lock(mutex);
        stats.kernel_drops = socket.kernelDrops();
        if (kind == DatagramKind::kOther) {
          ++stats.other_datagrams;
          if (!std::exchange(warned_other, true))
            logger().warn(
                "{}: a {}-byte datagram on port {} is neither a lidar ({} bytes) nor an IMU ({} "
                "bytes) packet of the metadata's profiles; such datagrams are counted and ignored",
                name, buffer.size(), socket.port(), lidar_bytes, imu_bytes);
          continue;
        }
        ++(stream == kLidar ? stats.lidar_packets : stats.imu_packets);
        queues[stream].push_back(buffer);
        stats.max_backlog =
            std::max(stats.max_backlog, queues[kLidar].size() + queues[kImu].size());
        arrived.notify_all();
      }
    }
  }
  close("the live capture was closed");
}

void LiveCapture::State::tapImu(std::span<const std::uint8_t> packet) {
  std::lock_guard lock(tap_mutex);
  if (!imu_tap) return;
  if (tap_decoder->decode(packet, tap_samples) != PacketStatus::kOk) return;
  for (const ImuSample& sample : tap_samples) imu_tap(sample);
}

bool LiveCapture::State::pop(Stream stream, std::vector<std::uint8_t>& buffer) {
  std::unique_lock lock(mutex);
  arrived.wait(lock, [&] { return !queues[stream].empty() || closed; });
  if (queues[stream].empty()) return false;
  buffer = std::move(queues[stream].front());
  queues[stream].pop_front();
  return true;
}

namespace {

/// One stream's datagrams from the receiver's queue.
class QueuedDatagrams final : public DatagramSource {
 public:
  QueuedDatagrams(std::shared_ptr<LiveCapture::State> state, Stream stream)
      : state_(std::move(state)), stream_(stream) {}
  std::optional<std::span<const std::uint8_t>> next() override {
    if (!state_->pop(stream_, buffer_)) return std::nullopt;
    return std::span<const std::uint8_t>(buffer_);
  }

 private:
  std::shared_ptr<LiveCapture::State> state_;
  Stream stream_;
  std::vector<std::uint8_t> buffer_;
};

/// The lidar stream, counting what the frame assembler found into the live statistics.
class LiveLidarStream final : public StreamSource {
 public:
  LiveLidarStream(std::shared_ptr<LiveCapture::State> state,
                  std::unique_ptr<OusterLidarSource> lidar)
      : state_(std::move(state)), lidar_(std::move(lidar)) {}
  std::string name() const override { return lidar_->name(); }
  std::optional<RecordingEvent> next() override {
    std::optional<AssembledFrame> frame = lidar_->nextFrame();
    std::lock_guard lock(state_->mutex);
    LiveStats& s = state_->stats;
    s.frames = lidar_->stats().frames;
    s.incomplete_frames = lidar_->stats().incomplete_frames;
    s.bad_packets = lidar_->stats().droppedPackets();
    if (!frame) return std::nullopt;
    s.missing_columns +=
        static_cast<std::uint64_t>(frame->columns_expected - frame->columns_received);
    return RecordingEvent(std::move(frame->scan));
  }

 private:
  std::shared_ptr<LiveCapture::State> state_;
  std::unique_ptr<OusterLidarSource> lidar_;
};

}  // namespace

LiveCapture::LiveCapture(const LiveOptions& options) : state_(std::make_shared<State>()) {
  State& s = *state_;
  s.options = options;
  s.info = readSensorInfo(options.metadata);
  if (s.info.lidar_profile != LidarProfile::kOff)
    s.lidar_bytes = LidarPacketLayout::of(s.info).packet_bytes;
  if (s.info.imu_profile != ImuProfile::kOff)
    s.imu_bytes = ImuPacketLayout::of(s.info).packet_bytes;
  const auto choose = [](std::uint16_t configured, std::uint16_t metadata, std::uint16_t fallback) {
    return configured != 0 ? configured : metadata != 0 ? metadata : fallback;
  };
  const std::uint16_t lidar_port =
      choose(options.lidar_port, s.info.udp_port_lidar, kDefaultLidarPort);
  const std::uint16_t imu_port = choose(options.imu_port, s.info.udp_port_imu, kDefaultImuPort);
  s.sockets.push_back(
      UdpSocket::bound(options.bind_address, lidar_port, options.socket_buffer_bytes));
  if (imu_port != lidar_port)
    s.sockets.push_back(
        UdpSocket::bound(options.bind_address, imu_port, options.socket_buffer_bytes));
  s.name = fmt::format("udp://{}:{}", options.bind_address,
                       imu_port == lidar_port ? fmt::format("{}", lidar_port)
                                              : fmt::format("{}+{}", lidar_port, imu_port));
  const int granted = s.sockets.front().receiveBufferBytes();
  if (granted < options.socket_buffer_bytes / 2)
    logger().warn(
        "{}: the system granted a {:.1f} MB receive buffer of the {:.1f} MB asked for; a busy "
        "machine may lose packets (raise net.core.rmem_max, or run as root)",
        s.name, granted / 1e6, options.socket_buffer_bytes / 1e6);
  logger().info("{}: listening for {} ({} lidar packets of {} bytes, IMU packets of {} bytes)",
                s.name, options.metadata.string(), s.info.lidar_profile_name, s.lidar_bytes,
                s.imu_bytes);
  s.receiver = std::thread([&s] { s.receive(); });
}

LiveCapture::~LiveCapture() {
  {
    std::lock_guard lock(state_->mutex);
    state_->stopping = true;
  }
  state_->receiver.join();
}

const SensorInfo& LiveCapture::info() const { return state_->info; }
const std::string& LiveCapture::name() const { return state_->name; }

Recording LiveCapture::recording(const RigConfig& rig) {
  const State& s = *state_;
  std::vector<std::unique_ptr<StreamSource>> streams;
  if (s.lidar_bytes > 0)
    streams.push_back(std::make_unique<LiveLidarStream>(
        state_, std::make_unique<OusterLidarSource>(
                    fmt::format("{} (lidar)", s.name),
                    std::make_unique<QueuedDatagrams>(state_, kLidar), s.info, s.options.decoder)));
  if (s.imu_bytes > 0)
    streams.push_back(std::make_unique<OusterImuSource>(
        fmt::format("{} (IMU)", s.name), std::make_unique<QueuedDatagrams>(state_, kImu), s.info,
        s.options.decoder));
  Recording recording(s.name, std::move(streams), rig.lidar_time_offset_s);
  recording.setGyroAxes(rig.gyro_axes);
  return recording;
}

void LiveCapture::setImuTap(std::function<void(const ImuSample&)> tap) {
  std::lock_guard lock(state_->tap_mutex);
  if (!state_->tap_decoder) state_->tap_decoder.emplace(state_->info, state_->options.decoder);
  state_->imu_tap = std::move(tap);
}

LiveStats LiveCapture::stats() const {
  std::lock_guard lock(state_->mutex);
  return state_->stats;
}

}  // namespace taiga::io::ouster
