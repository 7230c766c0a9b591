#pragma once
// Recordings: one time-ordered stream of scans, IMU samples and GNSS fixes, whatever the source
// (ROS1 bag, Ouster pcap + metadata JSON, or a folder of files).
//
// Each source format provides one StreamSource per sensor stream; MergedRecording merges them by
// event time. A scan's event time is the time of its last point, because a scan can be processed
// only once it is complete (and the IMU up to its end has arrived).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "taiga/core/point_cloud.hpp"
#include "taiga/core/recording_config.hpp"
#include "taiga/core/rig_config.hpp"
#include "taiga/core/sensor_samples.hpp"

namespace taiga::io {

/// One lidar sweep. Per-point times are absolute, on the IMU clock once the recording's lidar
/// clock offset is applied.
struct Scan {
  std::uint64_t index = 0;   ///< 0, 1, 2, ... in the order the stream delivers scans
  double t_start_s = 0.0;    ///< time of the scan's first firing (column), s
  double t_end_s = 0.0;      ///< time of the scan's last point, s: the scan's event time
  PointCloud cloud_in_lidar; ///< valid returns only (no NaN, no zero-range points)
  /// The per-point times were made up from the geometry (no time field: column or azimuth over
  /// recording.scan_period_s), not measured.
  bool times_invented = false;
  /// The lidar clock's offset (rig.lidar_time_offset_s, or the run's tracked value) that the
  /// Recording added to the times above.
  double lidar_time_offset_s = 0.0;
};

using RecordingEvent = std::variant<Scan, ImuSample, GnssFix>;

/// The time at which an event is complete: a scan's end, a sample's or a fix's time.
double eventTime(const RecordingEvent& event);

/// Adds offset_s to every time of the scan and to its lidar_time_offset_s.
void shiftScanTimes(Scan& scan, double offset_s);

/// One sensor stream of a recording, delivering events of one kind in non-decreasing time order.
class StreamSource {
 public:
  virtual ~StreamSource() = default;
  /// A short name for messages, e.g. "/os_cloud_node/points" or "capture.pcap (lidar)".
  virtual std::string name() const = 0;
  /// The next event, or nothing at the end of the stream. Throws InputError on corrupt input.
  virtual std::optional<RecordingEvent> next() = 0;
  /// What the stream found out about its data once it has delivered events, for `taiga info`:
  /// e.g. the point fields and how per-point times were read, or the IMU's acceleration unit.
  virtual std::vector<std::string> details() const { return {}; }
};

/// Counts of what a Recording had to repair, for reports and `taiga info`.
struct RecordingRepairs {
  std::size_t out_of_order_dropped = 0;  ///< events not after their stream's previous event
};

/// All streams of a recording merged into one sequence in event-time order.
///
/// Within a stream, an event whose time is not after the previous one is dropped with a warning
/// (drivers occasionally repeat a stamp); a stream that jumps back by more than
/// kMaxBackwardJump_s is an error, because the recording then mixes clocks. The lidar clock
/// offset is added to every scan time before merging, and the gyro's scale and axis errors are
/// taken out of every IMU reading.
class Recording {
 public:
  static constexpr double kMaxBackwardJump_s = 1.0;

  Recording(std::string source, std::vector<std::unique_ptr<StreamSource>> streams,
            double lidar_time_offset_s = 0.0);
  Recording(Recording&&) noexcept;
  Recording& operator=(Recording&&) noexcept;
  ~Recording();

  /// The next event in time order, or nothing at the end. Throws InputError on corrupt input.
  /// `stream_index`, when given, receives the index (in streamNames()) of the event's stream.
  std::optional<RecordingEvent> next(std::size_t* stream_index = nullptr);

  /// The file or directory the recording was opened from.
  const std::string& source() const { return source_; }
  std::vector<std::string> streamNames() const;
  /// details() of every stream, prefixed with the stream's name.
  std::vector<std::string> streamDetails() const;
  const RecordingRepairs& repairs() const { return repairs_; }
  /// The offset added to the scans read from now on (thread-safe: a run's reader thread may
  /// already have read a few scans ahead with the previous one). The streams are merged in time
  /// order after it, so the scans come after the IMU readings that precede them.
  void setLidarTimeOffset(double offset_s) { lidar_time_offset_s_->store(offset_s); }
  /// The gyro readings read from now on are corrected for the gyro's scale and axis errors
  /// (rig.gyro_axes): rate = M_reading_true^-1 * reading. openRecording sets the rig's.
  void setGyroAxes(const GyroAxes& axes);
  /// Takes the gyro's scale and axis errors out of `sample` as next() does (for samples that
  /// reach a reader before the recording delivers them, like a live sensor's IMU tap).
  void correctGyro(ImuSample& sample) const {
    if (M_true_reading_)
      sample.angular_velocity_imu_radps = *M_true_reading_ * sample.angular_velocity_imu_radps;
  }

 private:
  struct Stream;
  void refill(Stream& stream);

  std::string source_;
  std::vector<Stream> streams_;
  std::unique_ptr<std::atomic<double>> lidar_time_offset_s_;  // movable, unlike the atomic
  RecordingRepairs repairs_;
  std::optional<Eigen::Matrix3d> M_true_reading_;  // unset: the readings as they are
};

/// Opens a ROS1 bag (*.bag), an Ouster capture (*.pcap with its metadata JSON) or a folder
/// recording (a directory, see docs/recordings.md). Throws InputError naming the path and the
/// problem when it is none of these or cannot be read.
Recording openRecording(const std::filesystem::path& path, const RecordingConfig& recording,
                        const RigConfig& rig);

}  // namespace taiga::io
