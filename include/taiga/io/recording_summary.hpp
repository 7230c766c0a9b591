#pragma once
// What a recording contains and whether its timestamps look right: the data behind `taiga info`.
// Reading timestamps wrongly is where most users of lidar-inertial systems get stuck, so the
// summary checks them: per-point times increasing across each scan and spanning about the
// interval between scans, gaps in every stream, streams on different clocks.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "taiga/io/recording.hpp"
#include "taiga/io/rosbag.hpp"

namespace taiga::io {

struct StreamStats {
  std::string name;
  std::string kind;  ///< "lidar", "imu" or "gnss"
  std::size_t count = 0;
  double first_s = 0.0, last_s = 0.0;
  double rate_hz = 0.0;            ///< (count - 1) / (last - first)
  double median_interval_s = 0.0;
  double max_interval_s = 0.0;
  double max_interval_at_s = 0.0;  ///< time of the event after the largest gap
  std::size_t gaps = 0;            ///< intervals longer than the gap threshold of the stream's kind
};

struct ScanStats {
  std::size_t min_points = 0, median_points = 0, max_points = 0;
  double median_span_s = 0.0;          ///< median of (last point time - first point time)
  std::size_t scans_with_monotonic_times = 0;  ///< times non-decreasing along columns (or point order)
  std::size_t scans_with_invented_times = 0;   ///< no time field: made up from the geometry
  bool has_columns = false;
  bool has_rings = false;
  bool has_intensities = false;
};

struct ImuStats {
  double median_acceleration_mps2 = 0.0;  ///< median |a| (after unit conversion)
  double median_angular_rate_radps = 0.0;
  std::size_t with_orientation = 0;
};

struct GnssStats {
  std::size_t no_fix = 0, fix = 0, sbas = 0, gbas = 0;
  std::optional<double> median_horizontal_sigma_m;  ///< when covariances are reported
};

struct RecordingSummary {
  std::string source;
  std::string format;  ///< "ROS1 bag", "folder recording", "Ouster capture"
  double duration_s = 0.0;
  std::vector<BagTopicInfo> bag_topics;  ///< every topic of a bag, also those taiga does not read
  std::vector<StreamStats> streams;
  ScanStats scans;
  ImuStats imu;
  GnssStats gnss;
  RecordingRepairs repairs;
  std::vector<std::string> details;   ///< from the streams: fields, time interpretation, units
  std::vector<std::string> warnings;  ///< things the user should look at
  std::optional<std::string> error;   ///< set when reading stopped early; the rest covers what was read
};

/// Reads the whole recording. Errors in the data end the reading and land in `error` (the
/// summary of what came before is kept); errors opening it are thrown as InputError.
/// `on_scan(n)` is called after each scan, for progress displays.
RecordingSummary summarizeRecording(const std::filesystem::path& path, const RecordingConfig& recording,
                                    const RigConfig& rig, const std::function<void(std::size_t)>& on_scan = {});

/// Number of scans the recording announces without reading it (bag index, scan files), if known.
std::optional<std::size_t> announcedScanCount(const std::filesystem::path& path, const RecordingConfig& recording);

std::string formatSummaryText(const RecordingSummary& summary);
/// The same as one JSON object, for scripts.
std::string formatSummaryJson(const RecordingSummary& summary);

}  // namespace taiga::io
