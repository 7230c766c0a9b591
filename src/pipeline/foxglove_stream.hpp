#pragma once
// live.foxglove: a run watched over the Foxglove WebSocket protocol (stream/foxglove_server.hpp;
// docs/live.md, "Foxglove"). Channels, every message JSON in the map frame:
//   /taiga/pose       foxglove.PoseInFrame   each scan's pose as published (PoseStream)
//   /taiga/imu_pose   foxglove.PoseInFrame   the IMU-rate dead-reckoned pose (PoseStream)
//   /taiga/scan       foxglove.PointCloud    each scan as registered (deskewed, voxel-filtered)
//                                            at its pose as published
//   /taiga/keyframes  foxglove.PointCloud    each keyframe's scan, thinned, placed at its pose as
//                                            published: the growing map, one message per keyframe
//   /taiga/health     taiga.ScanHealth       each scan's status, reason and processing time
// Internal to the pipeline.

#include <memory>
#include <string>

#include "taiga/lie/se3.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/stream/foxglove_server.hpp"

namespace taiga::pipeline {

enum FoxgloveTopic : std::size_t {
  kPoseTopic,
  kImuPoseTopic,
  kScanTopic,
  kKeyframesTopic,
  kHealthTopic
};

/// The server with the channels above, on "host:port", answering plain HTTP with `http` (the
/// viewer's page); InputError naming the address when it is not one or cannot be served.
std::unique_ptr<stream::FoxgloveServer> startFoxglove(const std::string& host_port,
                                                      stream::HttpHandler http = {});

/// A foxglove.PoseInFrame message in the map frame.
std::string poseInFrameJson(double t_s, const lie::SE3& T_map_body);

/// Keyframes and scan health to the server's channels.
class FoxgloveMapStream final : public SlamObserver {
 public:
  explicit FoxgloveMapStream(stream::FoxgloveServer& server) : server_(server) {}
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;

 private:
  stream::FoxgloveServer& server_;
  lie::SE3 T_map_odom_;  ///< as published with the latest scan
};

}  // namespace taiga::pipeline
