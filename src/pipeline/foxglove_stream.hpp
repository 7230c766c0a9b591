#pragma once
// live.foxglove: a run watched over the Foxglove WebSocket protocol (stream/foxglove_server.hpp;
// docs/live.md, "Foxglove"). Channels, every message JSON in the map frame:
//   /taiga/pose            foxglove.PoseInFrame   each scan's pose as published, with its
//                                                 covariance (PoseStream)
//   /taiga/imu_pose        foxglove.PoseInFrame   the IMU-rate dead-reckoned pose (PoseStream)
//   /taiga/scan            foxglove.PointCloud    each scan as registered (deskewed,
//                                                 voxel-filtered) at its pose as published
//   /taiga/keyframes       foxglove.PointCloud    each keyframe's scan, thinned, placed at its pose
//                                                 as published, with its id: the growing map, one
//                                                 message per keyframe
//   /taiga/health          taiga.ScanHealth       each scan's status, reason and processing time
//   /taiga/local_map       foxglove.PointCloud    the odometry's local map (the points its
//                                                 registration searches), at each keyframe
//   /taiga/keyframe_poses  foxglove.PosesInFrame  every keyframe's pose in the mapping graph, after
//                                                 each keyframe it handled: the map corrected by
//                                                 loop closures (pose i is keyframe i)
//   /taiga/loops           taiga.LoopClosure      each accepted loop closure
//   /taiga/georef          taiga.GridPose         each scan's pose in the grid (EPSG) with 1-sigma,
//                                                 once the online georeference has an estimate
//   /taiga/fix             foxglove.LocationFix   the same as latitude and longitude (a map panel)
//   /taiga/trees           taiga.TreeList         the online tree map (mapping.trees) as it is
//                                                 rewritten: [x, y, ground z, DBH, height] per stem
// A client that subscribes late gets the keyframes so far (thinned further), the latest keyframe
// poses and tree list, and every loop closure first.
// Internal to the pipeline.

#include <memory>
#include <string>

#include "run_georef.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/lie/se3.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/stream/foxglove_server.hpp"
#include "taiga/trees/stem_detection.hpp"

namespace taiga::pipeline {

enum FoxgloveTopic : std::size_t {
  kPoseTopic,
  kImuPoseTopic,
  kScanTopic,
  kKeyframesTopic,
  kHealthTopic,
  kLocalMapTopic,
  kKeyframePosesTopic,
  kLoopsTopic,
  kGeorefTopic,
  kFixTopic,
  kTreesTopic
};

/// The server with the channels above, on "host:port", answering plain HTTP with `http` (the
/// viewer's page); InputError naming the address when it is not one or cannot be served.
std::unique_ptr<stream::FoxgloveServer> startFoxglove(const std::string& host_port,
                                                      stream::HttpHandler http = {});

/// A foxglove.PoseInFrame message in the map frame; with `covariance` (of [dp (map frame, m);
/// dtheta (body frame, rad)], row-major) as an extra field, which Foxglove ignores.
std::string poseInFrameJson(double t_s, const lie::SE3& T_map_body,
                            const std::optional<lie::Matrix6>& covariance = std::nullopt);

/// Scans, keyframes, scan health, the graph's corrections and the online georeference to the
/// server's channels. `odometry` is the system's (its local map); `gnss` (optional) the run's
/// GnssRecorder, told of each scan before this.
class FoxgloveMapStream final : public SlamObserver {
 public:
  FoxgloveMapStream(stream::FoxgloveServer& server, const Odometry& odometry,
                    const GnssRecorder* gnss);
  ~FoxgloveMapStream() override;
  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onKeyframe(std::uint64_t id, const ScanOutcome& scan) override;
  void onGraph(const mapping::Mapper& mapper) override;  // on the mapping thread
  /// The online tree map's list (OnlineTrees' on_list; any thread), kept for late clients.
  void publishTrees(const std::vector<trees::Stem>& stems);

 private:
  void publishGeoreference(double t_s);
  void publishLocalMap(double t_s);

  stream::FoxgloveServer& server_;
  const Odometry& odometry_;
  const GnssRecorder* gnss_;
  std::unique_ptr<geo::CoordinateConverter> grid_;  ///< the georeference's EPSG, when there is one
  lie::SE3 T_map_odom_;                             ///< as published with the latest scan
  std::size_t loop_attempts_seen_ = 0;              ///< mapping thread only
};

}  // namespace taiga::pipeline
