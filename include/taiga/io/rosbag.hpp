#pragma once
// ROS1 bags (format 2.0, uncompressed, bz2 or lz4 chunks) read and written without a ROS
// installation, through Debian's rosbag_storage.
//
// Read: sensor_msgs/PointCloud2 (scans, see point_fields.hpp for the time conventions),
// sensor_msgs/Imu and sensor_msgs/NavSatFix. Topics are configured, or picked by message type
// when there is exactly one candidate. Written: the same types, scans in the Ouster driver's
// PointCloud2 layout.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "taiga/io/recording.hpp"

namespace taiga::io {

struct BagTopicInfo {
  std::string topic;
  std::string datatype;  ///< e.g. "sensor_msgs/PointCloud2"
  std::size_t message_count = 0;
  double first_receive_time_s = 0.0;  ///< bag (receive) time, not the header stamp
  double last_receive_time_s = 0.0;
};

/// Topics of a bag, sorted by name. Throws InputError naming the file when it cannot be read.
std::vector<BagTopicInfo> listBagTopics(const std::filesystem::path& bag);

/// The topics chosen for each stream of a bag.
struct BagTopicSelection {
  std::string lidar;
  std::string imu;
  std::string gnss;  ///< empty when the bag has no GNSS
};

/// Applies the configured topic names, or picks the only topic of each message type. A missing
/// configured topic, a wrong type, or several candidates throw InputError listing the choices
/// and naming the configuration key.
BagTopicSelection selectBagTopics(const std::filesystem::path& bag, const std::vector<BagTopicInfo>& topics,
                                  const RecordingConfig& config);

/// The lidar, IMU and (if present) GNSS streams of a bag.
std::vector<std::unique_ptr<StreamSource>> openBagStreams(const std::filesystem::path& bag,
                                                          const RecordingConfig& recording, const RigConfig& rig);

enum class BagCompression { kNone, kLz4, kBz2 };

/// Size of an organized (sensor-image) cloud: rows = beams, columns = firings per sweep.
struct ScanGrid {
  std::uint32_t rows = 0;
  std::uint32_t columns = 0;
};

/// Point layouts of other drivers (BagWriter::writeScanAs).
enum class ScanLayout {
  kVelodyne,  ///< velodyne_pointcloud XYZIRT: x y z intensity (float32), ring (uint16), time
              ///< (float32, s after the header stamp); flat
  kXyzi,      ///< x y z intensity (float32) only, flat, no time: deskewed upstream, or untimed
};

/// Writes a bag. Message times in the bag are the events' times (a scan's end), so that the bag's
/// own order is the order in which the data become available.
class BagWriter {
 public:
  BagWriter(const std::filesystem::path& path, BagCompression compression = BagCompression::kLz4);
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// A scan as sensor_msgs/PointCloud2 in the Ouster driver's layout: x y z intensity (float32),
  /// t (uint32, ns after the header stamp = t_start_s), reflectivity and ring (uint16). With a
  /// grid, the cloud is organized (rows x columns, all-zero points where there is no return;
  /// the cloud must carry rings and columns); without, it is a flat list of the points.
  void writeScan(const std::string& topic, const std::string& frame_id, const Scan& scan,
                 std::optional<ScanGrid> grid = std::nullopt);
  /// A scan as a flat sensor_msgs/PointCloud2 in another driver's layout; the header stamp is
  /// t_start_s, the message time t_end_s.
  void writeScanAs(ScanLayout layout, const std::string& topic, const std::string& frame_id,
                   const Scan& scan);
  void writeImu(const std::string& topic, const std::string& frame_id, const ImuSample& imu);
  void writeGnss(const std::string& topic, const std::string& frame_id, const GnssFix& fix);
  /// Writes the index and closes the file; also done by the destructor.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace taiga::io
