#include "foxglove_stream.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "taiga/core/errors.hpp"
#include "taiga/core/live_config.hpp"

namespace taiga::pipeline {
namespace {

/// Points per cloud message at most: a keyframe's scan is thinned evenly to this many.
constexpr std::size_t kMaxCloudPoints = 30000;
constexpr int kFloat32 = 7;  // foxglove.NumericType

std::uint64_t nanoseconds(double t_s) {
  return static_cast<std::uint64_t>(std::llround(t_s * 1e9));
}

nlohmann::json timestamp(double t_s) {
  const std::uint64_t ns = nanoseconds(t_s);
  return {{"sec", ns / 1'000'000'000}, {"nsec", ns % 1'000'000'000}};
}

nlohmann::json pose(const lie::SE3& T) {
  const Eigen::Quaterniond q = T.rotation().quaternion();
  const Eigen::Vector3d& p = T.translation();
  return {{"position", {{"x", p.x()}, {"y", p.y()}, {"z", p.z()}}},
          {"orientation", {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}}}};
}

/// RFC 4648 base64: how bytes fields travel in Foxglove's JSON encoding.
std::string base64(const std::vector<unsigned char>& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t n = (bytes[i] << 16) | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0) |
                            (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

// Minimal JSON Schemas: Foxglove picks its panels by schema name; the schema documents fields.
const char* kPoseInFrameSchema =
    R"({"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object"}}})";
const char* kPointCloudSchema =
    R"({"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"pose":{"type":"object"},"point_stride":{"type":"integer"},"fields":{"type":"array"},"data":{"type":"string","contentEncoding":"base64"}}})";
const char* kHealthSchema =
    R"({"type":"object","properties":{"t_s":{"type":"number"},"status":{"type":"string"},"reason":{"type":"string"},"processing_ms":{"type":"number"},"points":{"type":"integer"}}})";

/// A foxglove.PointCloud of `cloud` (body frame) placed at T_map_body, thinned evenly to at
/// most kMaxCloudPoints: x, y, z, intensity as float32.
std::string pointCloudJson(double t_s, const lie::SE3& T_map_body, const PointCloud& cloud) {
  const std::size_t step = cloud.size() / kMaxCloudPoints + 1;
  std::vector<unsigned char> data;
  data.reserve(cloud.size() / step * 16);
  for (std::size_t i = 0; i < cloud.size(); i += step) {
    const float values[4] = {static_cast<float>(cloud.positions[i].x()),
                             static_cast<float>(cloud.positions[i].y()),
                             static_cast<float>(cloud.positions[i].z()),
                             i < cloud.intensities.size() ? cloud.intensities[i] : 0.0f};
    const auto* bytes = reinterpret_cast<const unsigned char*>(values);
    data.insert(data.end(), bytes, bytes + sizeof(values));
  }
  nlohmann::json fields = nlohmann::json::array();
  for (const auto& [name, offset] : {std::pair{"x", 0}, {"y", 4}, {"z", 8}, {"intensity", 12}})
    fields.push_back({{"name", name}, {"offset", offset}, {"type", kFloat32}});
  return nlohmann::json{
      {"timestamp", timestamp(t_s)}, {"frame_id", "map"}, {"pose", pose(T_map_body)},
      {"point_stride", 16},          {"fields", fields},  {"data", base64(data)}}
      .dump();
}

}  // namespace

std::unique_ptr<stream::FoxgloveServer> startFoxglove(const std::string& host_port,
                                                      stream::HttpHandler http) {
  const auto address = udpAddressPort(host_port);
  if (!address)
    throw InputError(fmt::format("{}: expected host:port, found '{}'",
                                 http ? "--view" : "live.foxglove", host_port));
  return std::make_unique<stream::FoxgloveServer>(
      address->first, address->second,
      std::vector<stream::FoxgloveChannel>{
          {"/taiga/pose", "foxglove.PoseInFrame", kPoseInFrameSchema},
          {"/taiga/imu_pose", "foxglove.PoseInFrame", kPoseInFrameSchema},
          {"/taiga/scan", "foxglove.PointCloud", kPointCloudSchema},
          {"/taiga/keyframes", "foxglove.PointCloud", kPointCloudSchema},
          {"/taiga/health", "taiga.ScanHealth", kHealthSchema}},
      "taiga", 64u << 20, std::move(http));
}

std::string poseInFrameJson(double t_s, const lie::SE3& T_map_body) {
  return nlohmann::json{
      {"timestamp", timestamp(t_s)}, {"frame_id", "map"}, {"pose", pose(T_map_body)}}
      .dump();
}

void FoxgloveMapStream::onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) {
  T_map_odom_ = T_map_odom;
  if (scan.source_cloud_in_body && server_.subscribed(kScanTopic))
    server_.publish(
        kScanTopic, nanoseconds(scan.t_s),
        pointCloudJson(scan.t_s, T_map_odom * scan.T_odom_body, *scan.source_cloud_in_body));
  if (!server_.subscribed(kHealthTopic)) return;
  server_.publish(kHealthTopic, nanoseconds(scan.t_s),
                  nlohmann::json{{"t_s", scan.t_s},
                                 {"status", scanStatusName(scan.health.status)},
                                 {"reason", scan.health.reason},
                                 {"processing_ms", scan.timing.total_ms},
                                 {"points", scan.source_points}}
                      .dump());
}

void FoxgloveMapStream::onKeyframe(std::uint64_t /*id*/, const ScanOutcome& scan) {
  if (!scan.keyframe_cloud_in_body || !server_.subscribed(kKeyframesTopic)) return;
  server_.publish(
      kKeyframesTopic, nanoseconds(scan.t_s),
      pointCloudJson(scan.t_s, T_map_odom_ * scan.T_odom_body, *scan.keyframe_cloud_in_body));
}

}  // namespace taiga::pipeline
