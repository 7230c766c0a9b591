#include "taiga/io/recording_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "taiga/core/errors.hpp"
#include "taiga/io/folder_recording.hpp"

namespace taiga::io {
namespace {

template <class T>
T median(std::vector<T> values) {
  if (values.empty()) return T{};
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Collects event times of one stream and finds its gaps.
struct StreamTimes {
  std::string kind;
  std::vector<double> times_s;

  StreamStats stats(const std::string& name) const {
    StreamStats s;
    s.name = name;
    s.kind = kind;
    s.count = times_s.size();
    if (times_s.empty()) return s;
    s.first_s = times_s.front();
    s.last_s = times_s.back();
    if (times_s.size() < 2) return s;
    s.rate_hz = (times_s.size() - 1) / (s.last_s - s.first_s);
    std::vector<double> intervals;
    for (std::size_t i = 1; i < times_s.size(); ++i) intervals.push_back(times_s[i] - times_s[i - 1]);
    s.median_interval_s = median(intervals);
    // A missing scan is a gap; IMU and GNSS jitter more, so only a long silence counts.
    const double threshold = s.median_interval_s * (kind == "lidar" ? 1.5 : 5.0);
    for (std::size_t i = 0; i < intervals.size(); ++i) {
      if (intervals[i] > threshold) ++s.gaps;
      if (intervals[i] > s.max_interval_s) {
        s.max_interval_s = intervals[i];
        s.max_interval_at_s = times_s[i + 1];
      }
    }
    return s;
  }
};

// Per-point times must grow with the column (the firing order); without columns, with the
// order of the points.
bool timesIncreaseAcrossScan(const PointCloud& cloud) {
  if (!cloud.hasColumns()) return std::is_sorted(cloud.times_s.begin(), cloud.times_s.end());
  std::map<std::uint16_t, std::pair<double, double>> range_by_column;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    auto [it, inserted] = range_by_column.try_emplace(cloud.columns[i], cloud.times_s[i], cloud.times_s[i]);
    if (!inserted) {
      it->second.first = std::min(it->second.first, cloud.times_s[i]);
      it->second.second = std::max(it->second.second, cloud.times_s[i]);
    }
  }
  double previous_max = -INFINITY;
  for (const auto& [column, range] : range_by_column) {
    if (range.first < previous_max) return false;
    previous_max = range.second;
  }
  return true;
}

std::string formatFromPath(const std::filesystem::path& path) {
  if (std::filesystem::is_directory(path)) return "folder recording";
  if (path.extension() == ".bag") return "ROS1 bag";
  if (path.extension() == ".pcap") return "Ouster capture";
  return "unknown";
}

void addWarnings(RecordingSummary& s, const std::vector<std::size_t>& points_per_scan, bool deskewed) {
  const StreamStats* lidar = nullptr;
  const StreamStats* imu = nullptr;
  for (const StreamStats& st : s.streams) {
    if (st.kind == "lidar") lidar = &st;
    if (st.kind == "imu") imu = &st;
    if (st.gaps > 0) {
      s.warnings.push_back(fmt::format("{}: {} gap(s) in the {} stream, the longest {:.3f} s before t = {:.6f} s", st.name,
                                       st.gaps, st.kind, st.max_interval_s, st.max_interval_at_s));
    }
  }
  if (!lidar || lidar->count == 0) s.warnings.push_back("no scans");
  if (!imu || imu->count == 0) s.warnings.push_back("no IMU samples: taiga run falls back to lidar-only odometry (odometry.imu_use: auto)");
  if (lidar && imu && lidar->count > 0 && imu->count > 0) {
    // Scans are listed by their start; the last one lasts until its last point.
    const double lidar_end_s = lidar->last_s + s.scans.median_span_s;
    if (lidar->first_s > imu->last_s || imu->first_s > lidar_end_s) {
      s.warnings.push_back(fmt::format("the lidar ({:.3f} .. {:.3f} s) and IMU ({:.3f} .. {:.3f} s) times do not overlap: "
                                       "different clocks? set rig.lidar_time_offset_s or fix the driver's time source",
                                       lidar->first_s, lidar_end_s, imu->first_s, imu->last_s));
    } else if (std::abs(lidar->first_s - imu->first_s) > 1.0) {
      s.warnings.push_back(fmt::format("the lidar and IMU streams start {:.3f} s apart", lidar->first_s - imu->first_s));
    }
  }
  if (s.scans.scans_with_invented_times > 0) {
    s.warnings.push_back(fmt::format("{} of {} scans have no per-point time field: taiga invents times from the geometry over "
                                     "recording.scan_period_s and deskews with them, unless the clouds were deskewed upstream "
                                     "(recording.deskewed: true, or auto: judged by the sweeps' seams)",
                                     s.scans.scans_with_invented_times, points_per_scan.size()));
  } else if (lidar && lidar->count >= 2 && lidar->median_interval_s > 0 && !deskewed) {
    const double ratio = s.scans.median_span_s / lidar->median_interval_s;
    if (ratio < 0.5 || ratio > 1.1) {
      s.warnings.push_back(fmt::format("per-point times span {:.4f} s per scan (median) but scans come every {:.4f} s: a "
                                       "wrong time unit or field? (recording.point_time_field)",
                                       s.scans.median_span_s, lidar->median_interval_s));
    }
  }
  if (s.scans.scans_with_monotonic_times < points_per_scan.size()) {
    s.warnings.push_back(fmt::format("per-point times do not increase across {} of {} scans",
                                     points_per_scan.size() - s.scans.scans_with_monotonic_times, points_per_scan.size()));
  }
  if (s.repairs.out_of_order_dropped > 0) {
    s.warnings.push_back(fmt::format("{} event(s) dropped for repeating or going back in time", s.repairs.out_of_order_dropped));
  }
}

}  // namespace

std::optional<std::size_t> announcedScanCount(const std::filesystem::path& path, const RecordingConfig& recording) {
  try {
    if (std::filesystem::is_directory(path)) return listFolderScans(path).size();
    if (path.extension() == ".bag") {
      const auto topics = listBagTopics(path);
      const std::string lidar = selectBagTopics(path, topics, recording).lidar;
      for (const BagTopicInfo& t : topics) {
        if (t.topic == lidar) return t.message_count;
      }
    }
  } catch (const InputError&) {  // the real reading reports the problem
  }
  return std::nullopt;
}

RecordingSummary summarizeRecording(const std::filesystem::path& path, const RecordingConfig& recording_config,
                                    const RigConfig& rig, const std::function<void(std::size_t)>& on_scan) {
  RecordingSummary s;
  s.source = path.string();
  s.format = formatFromPath(path);
  if (path.extension() == ".bag") s.bag_topics = listBagTopics(path);
  Recording recording = openRecording(path, recording_config, rig);

  std::vector<StreamTimes> times_by_stream(recording.streamNames().size());
  std::vector<std::size_t> points_per_scan;
  std::vector<double> spans, accelerations, rates, sigmas;
  try {
    std::size_t stream = 0;
    while (auto event = recording.next(&stream)) {
      StreamTimes& times = times_by_stream[stream];
      if (const auto* scan = std::get_if<Scan>(&*event)) {
        const PointCloud& cloud = scan->cloud_in_lidar;
        times.kind = "lidar";
        times.times_s.push_back(scan->t_start_s);
        points_per_scan.push_back(cloud.size());
        spans.push_back(scan->t_end_s - scan->t_start_s);
        if (timesIncreaseAcrossScan(cloud)) ++s.scans.scans_with_monotonic_times;
        s.scans.scans_with_invented_times += scan->times_invented;
        s.scans.has_columns |= cloud.hasColumns();
        s.scans.has_rings |= cloud.hasRings();
        s.scans.has_intensities |= cloud.hasIntensities();
        if (on_scan) on_scan(points_per_scan.size());
      } else if (const auto* imu = std::get_if<ImuSample>(&*event)) {
        times.kind = "imu";
        times.times_s.push_back(imu->t_s);
        accelerations.push_back(imu->acceleration_imu_mps2.norm());
        rates.push_back(imu->angular_velocity_imu_radps.norm());
        if (imu->orientation) ++s.imu.with_orientation;
      } else {
        const GnssFix& fix = std::get<GnssFix>(*event);
        times.kind = "gnss";
        times.times_s.push_back(fix.t_s);
        switch (fix.status) {
          case GnssStatus::kNoFix: ++s.gnss.no_fix; break;
          case GnssStatus::kFix: ++s.gnss.fix; break;
          case GnssStatus::kSbasFix: ++s.gnss.sbas; break;
          case GnssStatus::kGbasFix: ++s.gnss.gbas; break;
        }
        if (fix.covariance_type != GnssCovarianceType::kUnknown) {
          sigmas.push_back(std::sqrt(0.5 * (fix.covariance_enu_m2(0, 0) + fix.covariance_enu_m2(1, 1))));
        }
      }
    }
  } catch (const InputError& e) {
    s.error = e.what();
  }

  const std::vector<std::string> names = recording.streamNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!times_by_stream[i].times_s.empty()) s.streams.push_back(times_by_stream[i].stats(names[i]));
  }
  double first = INFINITY, last = -INFINITY;
  for (const StreamStats& st : s.streams) {
    if (st.count == 0) continue;
    first = std::min(first, st.first_s);
    last = std::max(last, st.last_s);
  }
  s.duration_s = last > first ? last - first : 0.0;
  if (!points_per_scan.empty()) {
    s.scans.min_points = *std::min_element(points_per_scan.begin(), points_per_scan.end());
    s.scans.max_points = *std::max_element(points_per_scan.begin(), points_per_scan.end());
    s.scans.median_points = median(points_per_scan);
    s.scans.median_span_s = median(spans);
  }
  s.imu.median_acceleration_mps2 = median(accelerations);
  s.imu.median_angular_rate_radps = median(rates);
  if (!sigmas.empty()) s.gnss.median_horizontal_sigma_m = median(sigmas);
  s.repairs = recording.repairs();
  s.details = recording.streamDetails();
  addWarnings(s, points_per_scan, recording_config.pointsAtStamp());
  return s;
}

std::string formatSummaryText(const RecordingSummary& s) {
  std::string out = fmt::format("recording  {} ({})\nduration   {:.3f} s\n", s.source, s.format, s.duration_s);
  if (!s.bag_topics.empty()) {
    out += "topics\n";
    for (const BagTopicInfo& t : s.bag_topics) out += fmt::format("  {:<32} {:<28} {:>8} messages\n", t.topic, t.datatype, t.message_count);
  }
  out += "streams\n";
  for (const StreamStats& st : s.streams) {
    out += fmt::format("  {:<32} {:<5} {:>8} events  {:8.2f} Hz  longest interval {:.3f} s\n", st.name, st.kind, st.count,
                       st.rate_hz, st.max_interval_s);
  }
  if (s.scans.max_points > 0) {
    out += fmt::format("scans      points per scan {} / {} / {} (min / median / max); per-point time span {:.4f} s (median); "
                       "times increase across {} scans\n",
                       s.scans.min_points, s.scans.median_points, s.scans.max_points, s.scans.median_span_s,
                       s.scans.scans_with_monotonic_times);
  }
  out += fmt::format("imu        |a| {:.3f} m/s^2, |w| {:.3f} rad/s (medians); {} samples with orientation\n",
                     s.imu.median_acceleration_mps2, s.imu.median_angular_rate_radps, s.imu.with_orientation);
  if (s.gnss.no_fix + s.gnss.fix + s.gnss.sbas + s.gnss.gbas > 0) {
    out += fmt::format("gnss       {} no fix, {} fix, {} SBAS, {} GBAS/RTK", s.gnss.no_fix, s.gnss.fix, s.gnss.sbas, s.gnss.gbas);
    if (s.gnss.median_horizontal_sigma_m) out += fmt::format("; horizontal sigma {:.2f} m (median)", *s.gnss.median_horizontal_sigma_m);
    out += "\n";
  }
  if (!s.details.empty()) {
    out += "details\n";
    for (const std::string& d : s.details) out += "  " + d + "\n";
  }
  if (!s.warnings.empty()) {
    out += "warnings\n";
    for (const std::string& w : s.warnings) out += "  " + w + "\n";
  }
  if (s.error) out += "error\n  " + *s.error + "\n";
  return out;
}

std::string formatSummaryJson(const RecordingSummary& s) {
  nlohmann::ordered_json j;
  j["source"] = s.source;
  j["format"] = s.format;
  j["duration_s"] = s.duration_s;
  j["bag_topics"] = nlohmann::json::array();
  for (const BagTopicInfo& t : s.bag_topics) {
    j["bag_topics"].push_back({{"topic", t.topic}, {"datatype", t.datatype}, {"messages", t.message_count}});
  }
  j["streams"] = nlohmann::json::array();
  for (const StreamStats& st : s.streams) {
    j["streams"].push_back({{"name", st.name}, {"kind", st.kind}, {"count", st.count}, {"first_s", st.first_s},
                            {"last_s", st.last_s}, {"rate_hz", st.rate_hz}, {"median_interval_s", st.median_interval_s},
                            {"max_interval_s", st.max_interval_s}, {"max_interval_at_s", st.max_interval_at_s},
                            {"gaps", st.gaps}});
  }
  j["scans"] = {{"min_points", s.scans.min_points},
                {"median_points", s.scans.median_points},
                {"max_points", s.scans.max_points},
                {"median_span_s", s.scans.median_span_s},
                {"scans_with_monotonic_times", s.scans.scans_with_monotonic_times},
                {"scans_with_invented_times", s.scans.scans_with_invented_times},
                {"has_rings", s.scans.has_rings},
                {"has_columns", s.scans.has_columns},
                {"has_intensities", s.scans.has_intensities}};
  j["imu"] = {{"median_acceleration_mps2", s.imu.median_acceleration_mps2},
              {"median_angular_rate_radps", s.imu.median_angular_rate_radps},
              {"with_orientation", s.imu.with_orientation}};
  j["gnss"] = {{"no_fix", s.gnss.no_fix}, {"fix", s.gnss.fix}, {"sbas", s.gnss.sbas}, {"gbas", s.gnss.gbas}};
  if (s.gnss.median_horizontal_sigma_m) j["gnss"]["median_horizontal_sigma_m"] = *s.gnss.median_horizontal_sigma_m;
  j["dropped_out_of_order"] = s.repairs.out_of_order_dropped;
  j["details"] = s.details;
  j["warnings"] = s.warnings;
  j["error"] = s.error ? nlohmann::json(*s.error) : nlohmann::json(nullptr);
  return j.dump(1) + "\n";
}

}  // namespace taiga::io
