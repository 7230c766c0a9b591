#include <fmt/format.h>
#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <deque>
#include <map>

#include "ros_messages.hpp"
#include "ros_time.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/io/imu_units.hpp"
#include "taiga/io/point_fields.hpp"
#include "taiga/io/rosbag.hpp"

namespace taiga::io {
namespace {

using detail::toSeconds;

constexpr const char* kPointCloudType = "sensor_msgs/PointCloud2";
constexpr const char* kImuType = "sensor_msgs/Imu";
constexpr const char* kNavSatFixType = "sensor_msgs/NavSatFix";

std::unique_ptr<rosbag::Bag> openBag(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(fmt::format("{}: {}", path.string(), std::filesystem::exists(path) ? "is not a file" : "no such file"));
  }
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path.string(), rosbag::bagmode::Read);
  } catch (const rosbag::BagUnindexedException&) {
    throw InputError(fmt::format("{}: the bag has no index, as when a recording is interrupted; rebuild it with "
                                 "`rosbag reindex` on a ROS installation",
                                 path.string()));
  } catch (const rosbag::BagException& e) {
    throw InputError(fmt::format("{}: cannot read the bag: {}", path.string(), e.what()));
  }
  return bag;
}

PackedPoints packedPointsOf(const detail::RosPointCloud2& msg) {
  PackedPoints points;
  for (const detail::RosPointField& f : msg.fields) {
    points.fields.push_back({std::string(f.name.begin(), f.name.end()), f.offset, static_cast<FieldType>(f.datatype), f.count});
  }
  points.width = msg.width;
  points.height = msg.height;
  points.point_step = msg.point_step;
  points.row_step = msg.row_step;
  points.is_bigendian = msg.is_bigendian;
  points.data = msg.data;
  return points;
}

ImuSample imuSampleOf(const detail::RosImu& msg) {
  ImuSample sample;
  sample.t_s = toSeconds(msg.header.stamp);
  sample.acceleration_imu_mps2 = {msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z};
  sample.angular_velocity_imu_radps = {msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z};
  const Eigen::Quaterniond q(msg.orientation.w, msg.orientation.x, msg.orientation.y, msg.orientation.z);
  // covariance[0] = -1 marks "no orientation" (sensor_msgs/Imu); an all-zero quaternion means the
  // same from drivers that forget the marker.
  if (msg.orientation_covariance[0] != -1.0 && q.norm() > 0.5) {
    sample.orientation = ImuOrientation{q.normalized(), OrientationReference::kEnu};  // REP-103
  }
  return sample;
}

GnssFix gnssFixOf(const detail::RosNavSatFix& msg) {
  GnssFix fix;
  fix.t_s = toSeconds(msg.header.stamp);
  fix.latitude_deg = msg.latitude;
  fix.longitude_deg = msg.longitude;
  fix.height_ellipsoid_m = msg.altitude;  // NavSatFix altitude is above the WGS84 ellipsoid
  fix.covariance_enu_m2 = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(msg.position_covariance.data());
  fix.covariance_type = static_cast<GnssCovarianceType>(std::min<int>(msg.position_covariance_type, 3));
  fix.status = static_cast<GnssStatus>(std::clamp<int>(msg.status.status, -1, 2));
  return fix;
}

// One pass over the bag for all selected topics, handing each stream its own messages in bag
// order: one View means each chunk is decompressed once, however many streams read it.
class BagDemux {
 public:
  BagDemux(const std::filesystem::path& path, const std::vector<std::string>& topics, const RecordingConfig& config)
      : path_(path), bag_(openBag(path)), view_(*bag_, rosbag::TopicQuery(topics)), it_(view_.begin()),
        point_options_{config.scan_period_s, config.point_time_field, config.pointsAtStamp()} {}

  std::optional<RecordingEvent> next(const std::string& topic) {
    std::deque<RecordingEvent>& queue = queues_[topic];
    while (queue.empty() && it_ != view_.end()) {
      const rosbag::MessageInstance& m = *it_;
      try {
        if (auto event = convert(m)) queues_[m.getTopic()].push_back(std::move(*event));
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: {}: message at bag time {:.6f} s: {}", path_.string(), m.getTopic(),
                                     toSeconds(m.getTime()), e.what()));
      } catch (const std::exception& e) {  // rosbag and ROS serialization errors: a corrupt bag
        throw InputError(fmt::format("{}: {}: message at bag time {:.6f} s cannot be read (corrupt or truncated "
                                     "bag?): {}",
                                     path_.string(), m.getTopic(), toSeconds(m.getTime()), e.what()));
      }
      ++it_;
    }
    if (queue.empty()) return std::nullopt;
    RecordingEvent event = std::move(queue.front());
    queue.pop_front();
    return event;
  }

  const std::filesystem::path& path() const { return path_; }
  const std::vector<std::string>& details(const std::string& topic) { return details_[topic]; }

 private:
  std::optional<RecordingEvent> convert(const rosbag::MessageInstance& m) {
    if (m.getDataType() == kPointCloudType) return convertScan(m);
    if (m.getDataType() == kImuType) return imuSampleOf(*m.instantiate<detail::RosImu>());
    if (m.getDataType() == kNavSatFixType) {
      const GnssFix fix = gnssFixOf(*m.instantiate<detail::RosNavSatFix>());
      if (std::isfinite(fix.latitude_deg) && std::isfinite(fix.longitude_deg) && std::isfinite(fix.height_ellipsoid_m)) {
        return fix;
      }
      if (invalid_fixes_++ == 0) logger().warn("{}: {}: skipping fixes without a position (NaN)", path_.string(), m.getTopic());
    }
    return std::nullopt;
  }

  std::optional<RecordingEvent> convertScan(const rosbag::MessageInstance& m) {
    const auto msg = m.instantiate<detail::RosPointCloud2>();
    DecodedPoints decoded = decodePackedPoints(packedPointsOf(*msg), toSeconds(msg->header.stamp), point_options_);
    if (!warned_time_source_) {
      warned_time_source_ = true;
      const PackedPoints packed = packedPointsOf(*msg);
      details_[m.getTopic()] = {fmt::format("point fields: {}", describeFields(packed.fields)),
                                fmt::format("cloud layout: {} x {}{}", packed.height, packed.width,
                                            packed.height > 1 ? " (organized)" : ""),
                                fmt::format("per-point times: {}", decoded.time_description)};
      if (timesInvented(decoded.time_source)) {
        logger().warn("{}: {}: per-point times: {}; deskewing is only as good as this guess (clouds deskewed "
                      "upstream: recording.deskewed: true)",
                      path_.string(), m.getTopic(), decoded.time_description);
      } else {
        logger().info("{}: {}: per-point times from {}", path_.string(), m.getTopic(), decoded.time_description);
      }
    }
    if (decoded.cloud.empty()) {
      if (empty_scans_++ == 0) logger().warn("{}: {}: skipping scans without any valid point", path_.string(), m.getTopic());
      return std::nullopt;
    }
    Scan scan;
    scan.index = scan_count_++;
    std::tie(scan.t_start_s, scan.t_end_s) = decoded.cloud.timeSpan();
    scan.cloud_in_lidar = std::move(decoded.cloud);
    scan.times_invented = timesInvented(decoded.time_source);
    return scan;
  }

  std::filesystem::path path_;
  std::unique_ptr<rosbag::Bag> bag_;
  rosbag::View view_;
  rosbag::View::iterator it_;
  PointDecodeOptions point_options_;
  std::map<std::string, std::deque<RecordingEvent>> queues_;
  std::map<std::string, std::vector<std::string>> details_;
  std::uint64_t scan_count_ = 0;
  std::size_t empty_scans_ = 0;
  std::size_t invalid_fixes_ = 0;
  bool warned_time_source_ = false;
};

class BagStream final : public StreamSource {
 public:
  BagStream(std::shared_ptr<BagDemux> demux, std::string topic) : demux_(std::move(demux)), topic_(std::move(topic)) {}
  std::string name() const override { return topic_; }
  std::optional<RecordingEvent> next() override { return demux_->next(topic_); }
  std::vector<std::string> details() const override { return demux_->details(topic_); }

 private:
  std::shared_ptr<BagDemux> demux_;
  std::string topic_;
};

std::string listTopics(const std::vector<BagTopicInfo>& topics) {
  std::string out;
  for (const BagTopicInfo& t : topics) out += fmt::format("\n  {} ({}, {} messages)", t.topic, t.datatype, t.message_count);
  return out.empty() ? " (none)" : out;
}

// The configured topic (checked) or the only topic of `datatype`; empty when optional and absent.
std::string pickTopic(const std::filesystem::path& bag, const std::vector<BagTopicInfo>& topics, const std::string& configured,
                      const char* datatype, const char* key, bool required) {
  if (!configured.empty()) {
    const auto it = std::find_if(topics.begin(), topics.end(), [&](const BagTopicInfo& t) { return t.topic == configured; });
    if (it == topics.end()) {
      throw InputError(fmt::format("{}: recording.{} is '{}' but the bag has no such topic; its topics:{}", bag.string(), key,
                                   configured, listTopics(topics)));
    }
    if (it->datatype != datatype) {
      throw InputError(fmt::format("{}: recording.{}: topic '{}' holds {}, expected {}", bag.string(), key, configured,
                                   it->datatype, datatype));
    }
    return configured;
  }
  std::vector<BagTopicInfo> candidates;
  std::copy_if(topics.begin(), topics.end(), std::back_inserter(candidates),
               [&](const BagTopicInfo& t) { return t.datatype == datatype; });
  if (candidates.size() == 1) return candidates.front().topic;
  if (candidates.empty()) {
    if (!required) return "";
    throw InputError(fmt::format("{}: no {} topic in the bag; its topics:{}", bag.string(), datatype, listTopics(topics)));
  }
  throw InputError(fmt::format("{}: several {} topics; choose one with recording.{} in the configuration:{}", bag.string(),
                               datatype, key, listTopics(candidates)));
}

}  // namespace

std::vector<BagTopicInfo> listBagTopics(const std::filesystem::path& path) {
  const auto bag = openBag(path);
  try {
    rosbag::View view(*bag);
    std::map<std::string, BagTopicInfo> by_topic;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) {
      BagTopicInfo& info = by_topic[c->topic];
      info.topic = c->topic;
      info.datatype = c->datatype;
      rosbag::View topic_view(*bag, rosbag::TopicQuery(c->topic));
      info.message_count = topic_view.size();
      if (info.message_count > 0) {
        info.first_receive_time_s = toSeconds(topic_view.getBeginTime());
        info.last_receive_time_s = toSeconds(topic_view.getEndTime());
      }
    }
    std::vector<BagTopicInfo> topics;
    for (auto& [name, info] : by_topic) topics.push_back(std::move(info));
    return topics;
  } catch (const rosbag::BagException& e) {
    throw InputError(fmt::format("{}: cannot read the bag index: {}", path.string(), e.what()));
  }
}

BagTopicSelection selectBagTopics(const std::filesystem::path& bag, const std::vector<BagTopicInfo>& topics,
                                  const RecordingConfig& config) {
  return {pickTopic(bag, topics, config.lidar_topic, kPointCloudType, "lidar_topic", true),
          pickTopic(bag, topics, config.imu_topic, kImuType, "imu_topic", false),
          pickTopic(bag, topics, config.gnss_topic, kNavSatFixType, "gnss_topic", false)};
}

std::vector<std::unique_ptr<StreamSource>> openBagStreams(const std::filesystem::path& bag, const RecordingConfig& recording,
                                                          const RigConfig& rig) {
  const BagTopicSelection selection = selectBagTopics(bag, listBagTopics(bag), recording);
  if (selection.imu.empty()) logger().warn("{}: the bag has no sensor_msgs/Imu topic", bag.string());
  std::vector<std::string> topics{selection.lidar};
  for (const std::string& topic : {selection.imu, selection.gnss}) {
    if (!topic.empty()) topics.push_back(topic);
  }
  auto demux = std::make_shared<BagDemux>(bag, topics, recording);

  std::vector<std::unique_ptr<StreamSource>> streams;
  streams.push_back(std::make_unique<BagStream>(demux, selection.lidar));
  if (!selection.imu.empty()) {
    streams.push_back(withAccelerationUnit(std::make_unique<BagStream>(demux, selection.imu), rig.imu_acceleration_unit,
                                           bag.string()));
  }
  if (!selection.gnss.empty()) streams.push_back(std::make_unique<BagStream>(demux, selection.gnss));
  return streams;
}

}  // namespace taiga::io
