#include <fmt/format.h>
#include <rosbag/bag.h>

#include <cmath>
#include <cstring>

#include "ros_messages.hpp"
#include "ros_time.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/rosbag.hpp"

namespace taiga::io {
namespace {

using detail::toRosTime;

// The Ouster driver's point record (ouster-ros, PointXYZIRT-like subset).
struct OusterRecord {
  float x, y, z;
  float intensity;
  std::uint32_t t_ns;  // after the header stamp
  std::uint16_t reflectivity;
  std::uint16_t ring;
};
static_assert(sizeof(OusterRecord) == 24);

// The Velodyne driver's point record (velodyne_pointcloud PointXYZIRT, packed).
struct VelodyneRecord {
  float x, y, z;
  float intensity;
  std::uint16_t ring;
  std::uint16_t padding;
  float time_s;  // after the header stamp
};
static_assert(sizeof(VelodyneRecord) == 24);

// A deskewed cloud as odometry front ends republish it: no time, no ring.
struct XyziRecord {
  float x, y, z;
  float intensity;
};
static_assert(sizeof(XyziRecord) == 16);

void addField(detail::RosPointCloud2& msg, const char* name, std::uint32_t offset, std::uint8_t datatype) {
  detail::RosPointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  msg.fields.push_back(field);
}

detail::RosHeader header(const std::string& frame_id, double t_s, std::uint32_t& seq) {
  detail::RosHeader h;
  h.seq = seq++;
  h.stamp = toRosTime(t_s);
  h.frame_id = frame_id.c_str();
  return h;
}

}  // namespace

struct BagWriter::Impl {
  std::filesystem::path path;
  rosbag::Bag bag;
  std::uint32_t seq = 0;
};

BagWriter::BagWriter(const std::filesystem::path& path, BagCompression compression) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  try {
    impl_->bag.open(path.string(), rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw InputError(fmt::format("{}: cannot create the bag: {}", path.string(), e.what()));
  }
  impl_->bag.setCompression(compression == BagCompression::kLz4   ? rosbag::compression::LZ4
                            : compression == BagCompression::kBz2 ? rosbag::compression::BZ2
                                                                  : rosbag::compression::Uncompressed);
}

BagWriter::~BagWriter() { close(); }

void BagWriter::close() {
  if (impl_->bag.isOpen()) impl_->bag.close();
}

void BagWriter::writeScan(const std::string& topic, const std::string& frame_id, const Scan& scan,
                          std::optional<ScanGrid> grid) {
  const PointCloud& cloud = scan.cloud_in_lidar;
  if (!cloud.hasTimes()) throw std::invalid_argument("BagWriter::writeScan: the cloud has no per-point times");
  if (grid && (!cloud.hasRings() || !cloud.hasColumns())) {
    throw std::invalid_argument("BagWriter::writeScan: an organized cloud needs rings and columns");
  }
  const ros::Time stamp = toRosTime(scan.t_start_s);
  const double stamp_s = detail::toSeconds(stamp);

  detail::RosPointCloud2 msg;
  msg.header = header(frame_id, scan.t_start_s, impl_->seq);
  addField(msg, "x", offsetof(OusterRecord, x), detail::RosPointField::FLOAT32);
  addField(msg, "y", offsetof(OusterRecord, y), detail::RosPointField::FLOAT32);
  addField(msg, "z", offsetof(OusterRecord, z), detail::RosPointField::FLOAT32);
  addField(msg, "intensity", offsetof(OusterRecord, intensity), detail::RosPointField::FLOAT32);
  addField(msg, "t", offsetof(OusterRecord, t_ns), detail::RosPointField::UINT32);
  addField(msg, "reflectivity", offsetof(OusterRecord, reflectivity), detail::RosPointField::UINT16);
  addField(msg, "ring", offsetof(OusterRecord, ring), detail::RosPointField::UINT16);
  msg.height = grid ? grid->rows : 1;
  msg.width = grid ? grid->columns : static_cast<std::uint32_t>(cloud.size());
  msg.point_step = sizeof(OusterRecord);
  msg.row_step = msg.width * msg.point_step;
  msg.is_bigendian = false;
  msg.is_dense = !grid;
  msg.data.assign(std::size_t{msg.row_step} * msg.height, 0);  // all-zero records: no return

  for (std::size_t i = 0; i < cloud.size(); ++i) {
    OusterRecord r{};
    r.x = static_cast<float>(cloud.positions[i].x());
    r.y = static_cast<float>(cloud.positions[i].y());
    r.z = static_cast<float>(cloud.positions[i].z());
    r.intensity = cloud.hasIntensities() ? cloud.intensities[i] : 0.0f;
    r.reflectivity = static_cast<std::uint16_t>(std::clamp(r.intensity, 0.0f, 65535.0f));
    r.t_ns = static_cast<std::uint32_t>(std::max(0.0, std::round((cloud.times_s[i] - stamp_s) * 1e9)));
    r.ring = cloud.hasRings() ? cloud.rings[i] : 0;
    std::size_t slot = i;
    if (grid) {
      if (cloud.rings[i] >= grid->rows || cloud.columns[i] >= grid->columns) {
        throw std::invalid_argument("BagWriter::writeScan: a point lies outside the grid");
      }
      slot = std::size_t{cloud.rings[i]} * grid->columns + cloud.columns[i];
    }
    std::memcpy(msg.data.data() + slot * sizeof(OusterRecord), &r, sizeof r);
  }
  impl_->bag.write(topic, toRosTime(scan.t_end_s), msg);
}

void BagWriter::writeScanAs(ScanLayout layout, const std::string& topic,
                            const std::string& frame_id, const Scan& scan) {
  const PointCloud& cloud = scan.cloud_in_lidar;
  const bool timed = layout == ScanLayout::kVelodyne;
  if (timed && !cloud.hasTimes())
    throw std::invalid_argument("BagWriter::writeScanAs: the cloud has no per-point times");
  const double stamp_s = detail::toSeconds(toRosTime(scan.t_start_s));
  detail::RosPointCloud2 msg;
  msg.header = header(frame_id, scan.t_start_s, impl_->seq);
  addField(msg, "x", 0, detail::RosPointField::FLOAT32);
  addField(msg, "y", 4, detail::RosPointField::FLOAT32);
  addField(msg, "z", 8, detail::RosPointField::FLOAT32);
  addField(msg, "intensity", 12, detail::RosPointField::FLOAT32);
  if (timed) {
    addField(msg, "ring", offsetof(VelodyneRecord, ring), detail::RosPointField::UINT16);
    addField(msg, "time", offsetof(VelodyneRecord, time_s), detail::RosPointField::FLOAT32);
  }
  msg.height = 1;
  msg.width = static_cast<std::uint32_t>(cloud.size());
  msg.point_step = timed ? sizeof(VelodyneRecord) : sizeof(XyziRecord);
  msg.row_step = msg.width * msg.point_step;
  msg.is_bigendian = false;
  msg.is_dense = true;
  msg.data.assign(std::size_t{msg.row_step}, 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    VelodyneRecord r{};
    r.x = static_cast<float>(cloud.positions[i].x());
    r.y = static_cast<float>(cloud.positions[i].y());
    r.z = static_cast<float>(cloud.positions[i].z());
    r.intensity = cloud.hasIntensities() ? cloud.intensities[i] : 0.0f;
    if (timed) {
      r.ring = cloud.hasRings() ? cloud.rings[i] : 0;
      r.time_s = static_cast<float>(cloud.times_s[i] - stamp_s);
    }
    std::memcpy(msg.data.data() + i * msg.point_step, &r, msg.point_step);
  }
  impl_->bag.write(topic, toRosTime(scan.t_end_s), msg);
}

void BagWriter::writeImu(const std::string& topic, const std::string& frame_id, const ImuSample& imu) {
  detail::RosImu msg;
  msg.header = header(frame_id, imu.t_s, impl_->seq);
  msg.linear_acceleration.x = imu.acceleration_imu_mps2.x();
  msg.linear_acceleration.y = imu.acceleration_imu_mps2.y();
  msg.linear_acceleration.z = imu.acceleration_imu_mps2.z();
  msg.angular_velocity.x = imu.angular_velocity_imu_radps.x();
  msg.angular_velocity.y = imu.angular_velocity_imu_radps.y();
  msg.angular_velocity.z = imu.angular_velocity_imu_radps.z();
  if (imu.orientation) {
    const Eigen::Quaterniond& q = imu.orientation->q_reference_imu;
    msg.orientation.x = q.x();
    msg.orientation.y = q.y();
    msg.orientation.z = q.z();
    msg.orientation.w = q.w();
  } else {
    msg.orientation_covariance[0] = -1.0;  // sensor_msgs/Imu: no orientation estimate
  }
  impl_->bag.write(topic, msg.header.stamp, msg);
}

void BagWriter::writeGnss(const std::string& topic, const std::string& frame_id, const GnssFix& fix) {
  detail::RosNavSatFix msg;
  msg.header = header(frame_id, fix.t_s, impl_->seq);
  msg.latitude = fix.latitude_deg;
  msg.longitude = fix.longitude_deg;
  msg.altitude = fix.height_ellipsoid_m;
  msg.status.status = static_cast<std::int8_t>(fix.status);
  msg.status.service = sensor_msgs::NavSatStatus_<detail::RosAllocator<void>>::SERVICE_GPS;
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(msg.position_covariance.data()) = fix.covariance_enu_m2;
  msg.position_covariance_type = static_cast<std::uint8_t>(fix.covariance_type);
  impl_->bag.write(topic, msg.header.stamp, msg);
}

}  // namespace taiga::io
