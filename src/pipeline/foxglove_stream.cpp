#include "foxglove_stream.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "taiga/core/errors.hpp"
#include "taiga/core/live_config.hpp"

namespace taiga::pipeline {
namespace {

/// Points per cloud message at most: a keyframe's scan is thinned evenly to this many, and to
/// kMaxHistoryPoints in what a late client gets (about 85 kB each: 3000 keyframes in 256 MB).
constexpr std::size_t kMaxCloudPoints = 30000;
constexpr std::size_t kMaxHistoryPoints = 4000;
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
const char* kPosesInFrameSchema =
    R"({"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"poses":{"type":"array"}}})";
const char* kLoopSchema =
    R"({"type":"object","properties":{"t_s":{"type":"number"},"keyframe":{"type":"integer"},"candidate":{"type":"integer"},"correction_m":{"type":"number"},"correction_deg":{"type":"number"}}})";
const char* kGridPoseSchema =
    R"({"type":"object","properties":{"t_s":{"type":"number"},"epsg":{"type":"integer"},"easting_m":{"type":"number"},"northing_m":{"type":"number"},"height_m":{"type":"number"},"yaw_grid_deg":{"type":"number"},"sigma":{"type":"array"},"fixes":{"type":"integer"}}})";
const char* kLocationFixSchema =
    R"({"type":"object","properties":{"timestamp":{"type":"object"},"frame_id":{"type":"string"},"latitude":{"type":"number"},"longitude":{"type":"number"},"altitude":{"type":"number"},"position_covariance":{"type":"array"},"position_covariance_type":{"type":"integer"}}})";
const char* kTreeListSchema =
    R"({"type":"object","properties":{"trees":{"type":"array","items":{"type":"array","description":"x, y, ground z, DBH, height; m"}}}})";
const char* kHealthSchema =
    R"({"type":"object","properties":{"t_s":{"type":"number"},"status":{"type":"string"},"reason":{"type":"string"},"processing_ms":{"type":"number"},"points":{"type":"integer"}}})";

/// A foxglove.PointCloud of `cloud` (body frame) placed at T_map_body, thinned evenly to at
/// most max_points: x, y, z, intensity as float32; `extra` adds fields (a keyframe's id).
std::string pointCloudJson(double t_s, const lie::SE3& T_map_body, const PointCloud& cloud,
                           std::size_t max_points = kMaxCloudPoints,
                           const nlohmann::json& extra = nlohmann::json::object()) {
  const std::size_t step = cloud.size() / max_points + 1;
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
  nlohmann::json message = {
      {"timestamp", timestamp(t_s)}, {"frame_id", "map"}, {"pose", pose(T_map_body)},
      {"point_stride", 16},          {"fields", fields},  {"data", base64(data)}};
  message.update(extra);
  return message.dump();
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
          {"/taiga/health", "taiga.ScanHealth", kHealthSchema},
          {"/taiga/local_map", "foxglove.PointCloud", kPointCloudSchema},
          {"/taiga/keyframe_poses", "foxglove.PosesInFrame", kPosesInFrameSchema},
          {"/taiga/loops", "taiga.LoopClosure", kLoopSchema},
          {"/taiga/georef", "taiga.GridPose", kGridPoseSchema},
          {"/taiga/fix", "foxglove.LocationFix", kLocationFixSchema},
          {"/taiga/trees", "taiga.TreeList", kTreeListSchema}},
      "taiga", 64u << 20, std::move(http));
}

std::string poseInFrameJson(double t_s, const lie::SE3& T_map_body,
                            const std::optional<lie::Matrix6>& covariance) {
  nlohmann::json message = {
      {"timestamp", timestamp(t_s)}, {"frame_id", "map"}, {"pose", pose(T_map_body)}};
  if (covariance)
    message["covariance"] = std::vector<double>(covariance->data(), covariance->data() + 36);
  return message.dump();
}

FoxgloveMapStream::FoxgloveMapStream(stream::FoxgloveServer& server, const Odometry& odometry,
                                     const GnssRecorder* gnss)
    : server_(server), odometry_(odometry), gnss_(gnss) {}

FoxgloveMapStream::~FoxgloveMapStream() = default;

void FoxgloveMapStream::onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) {
  T_map_odom_ = T_map_odom;
  if (scan.source_cloud_in_body && server_.subscribed(kScanTopic))
    server_.publish(
        kScanTopic, nanoseconds(scan.t_s),
        pointCloudJson(scan.t_s, T_map_odom * scan.T_odom_body, *scan.source_cloud_in_body));
  publishGeoreference(scan.t_s);
  if (!server_.subscribed(kHealthTopic)) return;
  server_.publish(kHealthTopic, nanoseconds(scan.t_s),
                  nlohmann::json{{"t_s", scan.t_s},
                                 {"status", scanStatusName(scan.health.status)},
                                 {"reason", scan.health.reason},
                                 {"processing_ms", scan.timing.total_ms},
                                 {"points", scan.source_points}}
                      .dump());
}

void FoxgloveMapStream::onKeyframe(std::uint64_t id, const ScanOutcome& scan) {
  if (!scan.keyframe_cloud_in_body) return;
  const lie::SE3 T_map_body = T_map_odom_ * scan.T_odom_body;
  const nlohmann::json keyframe = {{"keyframe", id}};
  const stream::FoxgloveServer::Kept thinned{pointCloudJson(
      scan.t_s, T_map_body, *scan.keyframe_cloud_in_body, kMaxHistoryPoints, keyframe)};
  server_.publish(kKeyframesTopic, nanoseconds(scan.t_s),
                  server_.subscribed(kKeyframesTopic)
                      ? pointCloudJson(scan.t_s, T_map_body, *scan.keyframe_cloud_in_body,
                                       kMaxCloudPoints, keyframe)
                      : std::string(),
                  &thinned);
  publishLocalMap(scan.t_s);
}

void FoxgloveMapStream::publishLocalMap(double t_s) {
  // Built only for subscribers (a late one gets it at the next keyframe): a copy of the local
  // map's points and their JSON cost milliseconds.
  const std::vector<Eigen::Vector3d>* points_in_odom = odometry_.localMap().pointsInUse();
  if (!points_in_odom || !server_.subscribed(kLocalMapTopic)) return;
  PointCloud cloud;
  cloud.positions = *points_in_odom;
  server_.publish(kLocalMapTopic, nanoseconds(t_s), pointCloudJson(t_s, T_map_odom_, cloud));
}

void FoxgloveMapStream::onGraph(const mapping::Mapper& mapper) {
  const Trajectory keyframes = mapper.keyframeTrajectory();
  if (keyframes.empty()) return;
  const double t_s = keyframes.back().t_s;
  nlohmann::json poses = nlohmann::json::array();
  for (const StampedPose& k : keyframes.poses()) poses.push_back(pose(k.pose));
  const stream::FoxgloveServer::Kept latest{
      nlohmann::json{{"timestamp", timestamp(t_s)}, {"frame_id", "map"}, {"poses", poses}}.dump(),
      /*replace=*/true};
  server_.publish(kKeyframePosesTopic, nanoseconds(t_s), latest.json, &latest);

  const std::vector<mapping::LoopRecord>& attempts = mapper.loopAttempts();
  for (; loop_attempts_seen_ < attempts.size(); ++loop_attempts_seen_) {
    const mapping::LoopRecord& record = attempts[loop_attempts_seen_];
    if (!record.attempt.accepted) continue;
    const stream::FoxgloveServer::Kept loop{nlohmann::json{
        {"t_s", record.t_s},
        {"keyframe", record.attempt.current},
        {"candidate", record.attempt.candidate.keyframe},
        {"correction_m", record.attempt.correction_m},
        {"correction_deg",
         record.attempt.correction_deg}}.dump()};
    server_.publish(kLoopsTopic, nanoseconds(record.t_s), loop.json, &loop);
  }
}

void FoxgloveMapStream::publishTrees(const std::vector<trees::Stem>& stems) {
  nlohmann::json rows = nlohmann::json::array();
  for (const trees::Stem& stem : stems) {
    const Eigen::Vector2d at = stem.axisAt(1.3);
    rows.push_back({at.x(), at.y(), stem.ground_z_m, stem.dbh_m, stem.height_m});
  }
  const stream::FoxgloveServer::Kept latest{nlohmann::json{{"trees", rows}}.dump(),
                                            /*replace=*/true};
  server_.publish(kTreesTopic, 0, latest.json, &latest);
}

void FoxgloveMapStream::publishGeoreference(double t_s) {
  const GnssRecorder::OnlineGridPose* online = gnss_ ? gnss_->onlinePoseAt(t_s) : nullptr;
  if (!online) return;
  const georef::GridPose& p = online->pose;
  const Eigen::Matrix<double, 6, 1>& sigma = online->sigma;
  if (server_.subscribed(kGeorefTopic))
    server_.publish(kGeorefTopic, nanoseconds(t_s),
                    nlohmann::json{{"t_s", t_s},
                                   {"epsg", gnss_->epsg()},
                                   {"easting_m", p.easting_m},
                                   {"northing_m", p.northing_m},
                                   {"height_m", p.height_m},
                                   {"yaw_grid_deg", p.yaw_grid_deg},
                                   {"sigma", std::vector<double>(sigma.data(), sigma.data() + 6)},
                                   {"fixes", online->fixes}}
                        .dump());
  if (!server_.subscribed(kFixTopic)) return;
  if (!grid_) grid_ = std::make_unique<geo::CoordinateConverter>(gnss_->epsg());
  const geo::Geodetic g = grid_->fromProjected({p.easting_m, p.northing_m, p.height_m});
  // East, north, up variances on the diagonal (ENU, row-major), as LocationFix has them.
  const std::vector<double> covariance = {
      sigma[0] * sigma[0], 0, 0, 0, sigma[1] * sigma[1], 0, 0, 0, sigma[2] * sigma[2]};
  server_.publish(kFixTopic, nanoseconds(t_s),
                  nlohmann::json{{"timestamp", timestamp(t_s)},
                                 {"frame_id", "map"},
                                 {"latitude", g.latitude_deg},
                                 {"longitude", g.longitude_deg},
                                 {"altitude", g.height_m},
                                 {"position_covariance", covariance},
                                 {"position_covariance_type", 2}}
                      .dump());
}

}  // namespace taiga::pipeline
