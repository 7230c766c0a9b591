#pragma once
// `taiga run --live`: where the sensor's packets arrive and how a live run behaves
// (io/ouster/live.hpp, docs/live.md).

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "taiga/core/config.hpp"

namespace taiga {

struct LiveConfig final : ConfigSection {
  /// The Ouster sensor's metadata JSON (as saved by the Ouster SDK, ouster-ros or
  /// `taiga simulate --pcap`): beam angles, packet profiles, ports.
  std::string metadata;
  std::string bind_address = "0.0.0.0";
  /// UDP ports; 0: the metadata's udp_port_lidar / udp_port_imu, else 7502 / 7503.
  int lidar_port = 0;
  int imu_port = 0;
  /// The run ends when no packet came for this long, s; 0: it waits until Ctrl-C.
  double idle_timeout_s = 10.0;
  double socket_buffer_mb = 64.0;
  /// Scans that may wait for the odometry before the oldest is dropped (a live run stays
  /// current rather than falling behind); dropped scans are reported. 5 (0.5 s at 10 Hz)
  /// absorbs the bursts of loop-closure verification on two cores.
  int max_queued_scans = 5;
  /// "host:port": every scan's and IMU sample's pose as a JSON datagram (docs/live.md, "Pose
  /// stream"), on a live run and on a recording alike; empty: none.
  std::string pose_udp;
  /// "host:port" of a Foxglove WebSocket server showing the run (poses, keyframes, health;
  /// docs/live.md, "Foxglove"), e.g. 0.0.0.0:8765; empty: none.
  std::string foxglove;

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

/// "host:port" split, or nothing when `text` is not one (port 1-65535).
std::optional<std::pair<std::string, std::uint16_t>> udpAddressPort(const std::string& text);

}  // namespace taiga
