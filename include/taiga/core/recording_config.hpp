#pragma once
// How to read a recording: which streams to take and how to interpret per-point times.

#include <string>

#include "taiga/core/config.hpp"

namespace taiga {

struct RecordingConfig final : ConfigSection {
  /// Topics of a ROS bag; empty picks the only topic of the right message type.
  std::string lidar_topic;
  std::string imu_topic;
  std::string gnss_topic;
  /// Ouster sensor metadata JSON for a pcap; empty looks next to the capture.
  std::string ouster_metadata;
  /// Duration of one lidar sweep, s; used when per-point times must be derived from geometry.
  double scan_period_s = 0.1;
  /// Point field holding per-point time; empty recognizes t, time, offset_time, timestamp.
  std::string point_time_field;
  /// Whether the clouds were deskewed (motion-compensated) upstream into the lidar frame at the
  /// message stamp: then every point is taken at the stamp and nothing is deskewed again. Auto:
  /// clouds with per-point times are raw sweeps; for clouds without, `taiga run` and
  /// `taiga calibrate` tell from the sweeps' seams (pipeline/sweep_check.hpp) and say what they
  /// found.
  enum class Deskewed { kAuto, kYes, kNo };
  Deskewed deskewed = Deskewed::kAuto;
  /// Every point at the stamp: deskewed upstream, as configured or as the sweep check found.
  bool pointsAtStamp() const { return deskewed == Deskewed::kYes; }

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
