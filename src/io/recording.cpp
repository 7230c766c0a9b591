#include "taiga/io/recording.hpp"

#include <fmt/format.h>

#include <limits>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/io/folder_recording.hpp"
#include "taiga/io/ouster/capture.hpp"
#include "taiga/io/rosbag.hpp"

namespace taiga::io {

double eventTime(const RecordingEvent& event) {
  struct {
    double operator()(const Scan& scan) const { return scan.t_end_s; }
    double operator()(const ImuSample& imu) const { return imu.t_s; }
    double operator()(const GnssFix& fix) const { return fix.t_s; }
  } visitor;
  return std::visit(visitor, event);
}

void shiftScanTimes(Scan& scan, double offset_s) {
  scan.t_start_s += offset_s;
  scan.t_end_s += offset_s;
  for (double& t : scan.cloud_in_lidar.times_s) t += offset_s;
  scan.lidar_time_offset_s += offset_s;
}

struct Recording::Stream {
  std::unique_ptr<StreamSource> source;
  std::optional<RecordingEvent> head;  // the next event of this stream, already read
  double last_time_s = -std::numeric_limits<double>::infinity();
  bool exhausted = false;
};

Recording::Recording(std::string source, std::vector<std::unique_ptr<StreamSource>> streams,
                     double lidar_time_offset_s)
    : source_(std::move(source)),
      lidar_time_offset_s_(std::make_unique<std::atomic<double>>(lidar_time_offset_s)) {
  for (auto& s : streams) streams_.push_back(Stream{std::move(s), std::nullopt});
}

void Recording::setGyroAxes(const GyroAxes& axes) {
  if (axes.isIdentity())
    M_true_reading_.reset();
  else
    M_true_reading_ = axes.M_reading_true.inverse();
}

Recording::Recording(Recording&&) noexcept = default;
Recording& Recording::operator=(Recording&&) noexcept = default;
Recording::~Recording() = default;

std::vector<std::string> Recording::streamNames() const {
  std::vector<std::string> names;
  for (const Stream& s : streams_) names.push_back(s.source->name());
  return names;
}

std::vector<std::string> Recording::streamDetails() const {
  std::vector<std::string> out;
  for (const Stream& s : streams_) {
    for (const std::string& detail : s.source->details()) out.push_back(s.source->name() + ": " + detail);
  }
  return out;
}

// Reads the stream's next event that is in time order, dropping (and counting) repeats.
void Recording::refill(Stream& stream) {
  while (!stream.head && !stream.exhausted) {
    std::optional<RecordingEvent> event = stream.source->next();
    if (!event) {
      stream.exhausted = true;
      return;
    }
    if (auto* scan = std::get_if<Scan>(&*event))
      shiftScanTimes(*scan, lidar_time_offset_s_->load());
    else if (auto* imu = std::get_if<ImuSample>(&*event))
      correctGyro(*imu);
    const double t_s = eventTime(*event);
    if (t_s > stream.last_time_s) {
      stream.last_time_s = t_s;
      stream.head = std::move(event);
      return;
    }
    if (stream.last_time_s - t_s > kMaxBackwardJump_s) {
      throw InputError(fmt::format(
          "{}: {}: time jumps back by {:.3f} s (from {:.6f} to {:.6f} s); the recording mixes clocks or "
          "joins several recordings",
          source_, stream.source->name(), stream.last_time_s - t_s, stream.last_time_s, t_s));
    }
    if (repairs_.out_of_order_dropped++ < 10) {
      logger().warn("{}: {}: dropped an event at {:.6f} s that is not after the previous one ({:.6f} s)", source_,
                    stream.source->name(), t_s, stream.last_time_s);
    }
  }
}

std::optional<RecordingEvent> Recording::next(std::size_t* stream_index) {
  Stream* earliest = nullptr;
  for (Stream& stream : streams_) {
    refill(stream);
    // Ties go to the stream listed first, so that the order is the same run after run.
    if (stream.head && (!earliest || eventTime(*stream.head) < eventTime(*earliest->head))) earliest = &stream;
  }
  if (!earliest) return std::nullopt;
  if (stream_index) *stream_index = static_cast<std::size_t>(earliest - streams_.data());
  std::optional<RecordingEvent> event;
  event.swap(earliest->head);
  return event;
}

namespace {

/// The metadata JSON of an Ouster capture: the configured one, else one beside the capture whose
/// name is the capture's name or its beginning (Ouster's tools save `NAME.json` with `NAME.pcap`,
/// `NAME_0.json` with a sensor index, or one JSON for several captures `NAME_part.pcap`).
std::filesystem::path findOusterMetadata(const std::filesystem::path& pcap, const RecordingConfig& recording) {
  if (!recording.ouster_metadata.empty()) {
    if (!std::filesystem::exists(recording.ouster_metadata)) {
      throw InputError(fmt::format("{}: no such file (recording.ouster_metadata, the sensor metadata for {})",
                                   recording.ouster_metadata, pcap.string()));
    }
    return recording.ouster_metadata;
  }
  const std::string stem = pcap.stem().string();
  for (const std::string& name : {stem + ".json", stem + "_0.json"}) {
    const std::filesystem::path candidate = pcap.parent_path() / name;
    if (std::filesystem::exists(candidate)) return candidate;
  }
  std::filesystem::path best;
  std::size_t best_length = 0;
  const std::filesystem::path dir = pcap.parent_path().empty() ? "." : pcap.parent_path();
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    const std::string json_stem = entry.path().stem().string();
    if (json_stem.size() > best_length && stem.starts_with(json_stem)) {
      best = entry.path();
      best_length = json_stem.size();
    }
  }
  if (best.empty()) {
    throw InputError(fmt::format("{}: an Ouster capture needs the sensor metadata JSON saved with it; none found "
                                 "beside it ({}.json, {}_0.json); give it with recording.ouster_metadata",
                                 pcap.string(), stem, stem));
  }
  logger().info("{}: using the sensor metadata {}", pcap.string(), best.string());
  return best;
}

}  // namespace

Recording openRecording(const std::filesystem::path& path, const RecordingConfig& recording, const RigConfig& rig) {
  if (!std::filesystem::exists(path)) throw InputError(fmt::format("{}: no such file or directory", path.string()));
  std::vector<std::unique_ptr<StreamSource>> streams;
  if (std::filesystem::is_directory(path)) {
    if (!isFolderRecording(path)) {
      throw InputError(fmt::format("{}: a directory without scans/ or imu.csv is not a folder recording (see "
                                   "docs/recordings.md)",
                                   path.string()));
    }
    streams = openFolderStreams(path, recording, rig);
  } else if (path.extension() == ".bag") {
    streams = openBagStreams(path, recording, rig);
  } else if (path.extension() == ".pcap" || path.extension() == ".pcapng") {
    streams = ouster::openOusterCapture(path, findOusterMetadata(path, recording));
  } else {
    throw InputError(fmt::format("{}: not a recording taiga reads: expected a ROS1 bag (.bag), an Ouster capture "
                                 "(.pcap) or a folder recording",
                                 path.string()));
  }
  Recording opened(path.string(), std::move(streams), rig.lidar_time_offset_s);
  opened.setGyroAxes(rig.gyro_axes);
  return opened;
}

}  // namespace taiga::io
