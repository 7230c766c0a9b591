#include "taiga/core/recording_config.hpp"

#include <array>
#include <string_view>
#include <utility>

namespace taiga {

void RecordingConfig::visit(ConfigVisitor& v) {
  v.field("lidar_topic", lidar_topic, "ROS bag topic of sensor_msgs/PointCloud2 scans; empty: the only one");
  v.field("imu_topic", imu_topic, "ROS bag topic of sensor_msgs/Imu; empty: the only one");
  v.field("gnss_topic", gnss_topic, "ROS bag topic of sensor_msgs/NavSatFix; empty: the only one, if any");
  v.field("ouster_metadata", ouster_metadata, "Ouster metadata JSON for a pcap; empty: found next to it");
  v.field("scan_period_s", scan_period_s, "s, one lidar sweep; used only to derive missing point times");
  v.field("point_time_field", point_time_field,
          "point field with per-point time; empty: t, time, offset_time or timestamp");
  static constexpr std::array<std::pair<std::string_view, Deskewed>, 3> kDeskewed{{
      {"auto", Deskewed::kAuto},
      {"true", Deskewed::kYes},
      {"false", Deskewed::kNo},
  }};
  enumField(v, "deskewed", deskewed, kDeskewed,
            "true: the clouds were deskewed upstream into the lidar frame at the message stamp; "
            "every point is taken at the stamp and not deskewed again. auto: clouds without "
            "per-point times are judged by their sweeps' seams");
}

void RecordingConfig::validate() const {
  requireInRange("scan_period_s", scan_period_s, 0.01, 1.0, "s");
}

}  // namespace taiga
