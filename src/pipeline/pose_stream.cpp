#include "pose_stream.hpp"

#include <fmt/format.h>

#include <cmath>

#include "foxglove_stream.hpp"
#include "motion_prior.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/live_config.hpp"

namespace taiga::pipeline {
namespace {

/// Samples kept to carry a new scan's state forward: far more than arrive during a scan's
/// processing, at any IMU rate.
constexpr std::size_t kMaxRecentSamples = 2000;
/// IMU-rate poses further than this from the latest scan pose are not sent: dead reckoning
/// drifts by centimetres in half a second (13 cm in 1 s on a handheld walk), metres in seconds.
constexpr double kMaxDeadReckoning_s = 0.5;

io::UdpSocket openSocket(const std::string& address) {
  const auto host_port = udpAddressPort(address);
  if (!host_port)
    throw InputError(fmt::format("live.pose_udp: expected host:port, found '{}'", address));
  return io::UdpSocket::connected(host_port->first, host_port->second);
}

}  // namespace

PoseStream::PoseStream(const std::string& udp_address, stream::FoxgloveServer* foxglove,
                       const SystemConfig& config, bool imu_from_system)
    : foxglove_(foxglove),
      imu_from_system_(imu_from_system),
      R_body_imu_(config.rig.T_body_imu.rotation()),
      gravity_mps2_(config.odometry.imu.gravity_mps2) {
  if (!udp_address.empty()) socket_ = openSocket(udp_address);
}

void PoseStream::send(const char* type, double t_s, const imu::NavState& s, const char* status,
                      const std::optional<lie::Matrix6>& covariance) {
  ++sent_;
  if (foxglove_ != nullptr) {
    const std::size_t topic = status != nullptr ? kPoseTopic : kImuPoseTopic;
    if (foxglove_->subscribed(topic))
      foxglove_->publish(topic, static_cast<std::uint64_t>(std::llround(t_s * 1e9)),
                         poseInFrameJson(t_s, lie::SE3(s.R_world_body, s.p_world), covariance));
  }
  if (!socket_) return;
  const Eigen::Quaterniond q = s.R_world_body.quaternion();
  std::string text = fmt::format(
      R"({{"type":"{}","t_s":{:.6f},"frame":"map","p":[{:.4f},{:.4f},{:.4f}],"q":[{:.6f},{:.6f},{:.6f},{:.6f}],"v":[{:.4f},{:.4f},{:.4f}])",
      type, t_s, s.p_world.x(), s.p_world.y(), s.p_world.z(), q.x(), q.y(), q.z(), q.w(),
      s.v_world.x(), s.v_world.y(), s.v_world.z());
  if (status != nullptr) text += fmt::format(R"(,"status":"{}")", status);
  if (covariance) {
    const lie::Vector6 sigma = covariance->diagonal().cwiseSqrt();
    text += fmt::format(R"(,"sigma_m":[{:.4f},{:.4f},{:.4f}],"sigma_deg":[{:.4f},{:.4f},{:.4f}])",
                        sigma[0], sigma[1], sigma[2], sigma[3] * kDegPerRad, sigma[4] * kDegPerRad,
                        sigma[5] * kDegPerRad);
    text += fmt::format(R"(,"cov":[{:.4e}])",
                        fmt::join(covariance->data(), covariance->data() + 36, ","));
  }
  if (status == nullptr) text += fmt::format(R"(,"age_s":{:.3f})", t_s - anchor_->t_s);
  text += "}\n";
  socket_->send(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void PoseStream::onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) {
  std::lock_guard lock(mutex_);
  const lie::SE3 T_map_body = T_map_odom * scan.T_odom_body;
  const Eigen::Matrix3d R_map_odom = T_map_odom.rotation().matrix();
  Anchor anchor{
      .t_s = scan.t_s,
      .state = {T_map_body.rotation(), T_map_body.translation(), R_map_odom * scan.v_odom},
      .bias = scan.bias,
      .gravity_map = R_map_odom * Eigen::Vector3d(0.0, 0.0, -gravity_mps2_)};
  send("scan", scan.t_s, anchor.state, scanStatusName(scan.health.status),
       scan.covariance ? std::optional(rotatedCovariance(*scan.covariance, T_map_odom.rotation()))
                       : std::nullopt);
  anchor_ = anchor;
  current_ = {anchor.t_s, anchor.state};
  // The samples that arrived after the scan's end are carried forward from the new anchor
  // (without sending again: they were sent from the previous one).
  while (!recent_.empty() && recent_.front().t_s <= anchor.t_s) recent_.pop_front();
  for (const ImuSample& s : recent_) carryTo(s);
}

void PoseStream::carryTo(const ImuSample& s) {
  // The reading held from the previous state to this sample (imu/readings.hpp's pieces would
  // average neighbours; live, the next sample is not there yet).
  const Eigen::Vector3d a = s.acceleration_imu_mps2 - anchor_->bias.accel_mps2;
  const Eigen::Vector3d w = s.angular_velocity_imu_radps - anchor_->bias.gyro_radps;
  current_.state = imu::propagate(current_.state, a, w, s.t_s - current_.t_s, anchor_->gravity_map);
  current_.t_s = s.t_s;
}

void PoseStream::advance(const ImuSample& s) {
  recent_.push_back(s);
  if (recent_.size() > kMaxRecentSamples) recent_.pop_front();
  if (!anchor_ || s.t_s <= current_.t_s) return;
  // A stale anchor: the scans held before levelling, released as one burst, or a lidar outage.
  if (s.t_s - anchor_->t_s > kMaxDeadReckoning_s) return;
  carryTo(s);
  send("imu", s.t_s, current_.state, nullptr);
}

void PoseStream::onImu(const ImuSample& sample) {
  if (imu_from_system_) imuArrived(sample);
}

void PoseStream::imuArrived(const ImuSample& sample) {
  ImuSample body = sample;
  body.acceleration_imu_mps2 = R_body_imu_ * sample.acceleration_imu_mps2;
  body.angular_velocity_imu_radps = R_body_imu_ * sample.angular_velocity_imu_radps;
  std::lock_guard lock(mutex_);
  advance(body);
}

std::size_t PoseStream::sent() const {
  std::lock_guard lock(mutex_);
  return sent_;
}

}  // namespace taiga::pipeline
