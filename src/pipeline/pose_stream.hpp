#pragma once
// The body's pose sent as it is known: to live.pose_udp, one JSON object per UDP datagram, for
// controllers and displays that do not speak WebSocket (docs/live.md, "Pose stream"), and to the
// Foxglove server's /taiga/pose and /taiga/imu_pose channels (foxglove_stream.hpp):
//   {"type":"scan","t_s":...,"frame":"map","p":[x,y,z],"q":[qx,qy,qz,qw],"v":[vx,vy,vz],
//    "status":"ok"}                                 each scan's pose, T_map_body at the scan's end
//   {"type":"imu","t_s":...,"frame":"map","p":[...],"q":[...],"v":[...],"age_s":0.035}
//                                                   each IMU sample's pose, dead-reckoned from
//                                                   the latest scan pose (imu/propagation.hpp)
//                                                   age_s ago, at most 0.5 s
// IMU samples come either through the SLAM system (onImu, in time order: a recording) or, on a
// live sensor, straight from the receiver as packets arrive (imuArrived, another thread), so
// that an IMU-rate pose leaves a few milliseconds after its packet instead of after the scan it
// falls into. Internal to the pipeline.

#include <deque>
#include <mutex>
#include <optional>
#include <string>

#include "taiga/core/system_config.hpp"
#include "taiga/imu/propagation.hpp"
#include "taiga/io/udp_socket.hpp"
#include "taiga/pipeline/slam_system.hpp"
#include "taiga/stream/foxglove_server.hpp"

namespace taiga::pipeline {

class PoseStream final : public SlamObserver {
 public:
  /// `udp_address` "host:port" (empty: no datagrams; InputError naming live.pose_udp when it is
  /// not one); `foxglove`: the server to publish on too, or null.
  /// `imu_from_system`: IMU samples arrive through onImu (else through imuArrived).
  PoseStream(const std::string& udp_address, stream::FoxgloveServer* foxglove,
             const SystemConfig& config, bool imu_from_system);

  void onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) override;
  void onImu(const ImuSample& sample) override;
  /// A sample in the IMU frame as it arrived from the sensor; thread-safe.
  void imuArrived(const ImuSample& sample);

  std::size_t sent() const;

 private:
  /// One pose to every output; `status` is the scan's, null for an IMU-rate pose.
  /// `covariance`: the scan pose's, [dp (map frame); dtheta (body)] (scans only).
  void send(const char* type, double t_s, const imu::NavState& state, const char* status,
            const std::optional<lie::Matrix6>& covariance = std::nullopt);
  /// Carries the dead-reckoned state forward to `sample` and sends it; with the lock held.
  void advance(const ImuSample& sample_body);
  /// Dead-reckons the current state to `sample` with the anchor's bias and gravity.
  void carryTo(const ImuSample& sample_body);

  std::optional<io::UdpSocket> socket_;
  stream::FoxgloveServer* foxglove_;
  const bool imu_from_system_;
  const lie::SO3 R_body_imu_;
  const double gravity_mps2_;
  mutable std::mutex mutex_;
  /// The latest scan's state in the map frame, its bias and gravity there, and the state
  /// dead-reckoned from it up to the last sample.
  struct Anchor {
    double t_s;
    imu::NavState state;
    imu::ImuBias bias;
    Eigen::Vector3d gravity_map;
  };
  std::optional<Anchor> anchor_;
  imu::StampedNavState current_;
  std::deque<ImuSample> recent_;  ///< body frame, newer than the anchor's time
  std::size_t sent_ = 0;
};

}  // namespace taiga::pipeline
