#include "taiga/core/live_config.hpp"

#include <charconv>

namespace taiga {

void LiveConfig::visit(ConfigVisitor& v) {
  v.field("metadata", metadata,
          "the Ouster sensor's metadata JSON (beam angles, packet profiles, ports)");
  v.field("bind_address", bind_address, "local address to receive on; 0.0.0.0: every interface");
  v.field("lidar_port", lidar_port, "UDP port of lidar packets; 0: the metadata's, else 7502");
  v.field("imu_port", imu_port, "UDP port of IMU packets; 0: the metadata's, else 7503");
  v.field("idle_timeout_s", idle_timeout_s,
          "s without a packet after which the run ends; 0: it waits until Ctrl-C");
  v.field("socket_buffer_mb", socket_buffer_mb, "MB of receive buffer per socket");
  v.field("max_queued_scans", max_queued_scans,
          "scans that may wait for the odometry before the oldest is dropped");
  v.field("pose_udp", pose_udp,
          "host:port receiving every scan's and IMU sample's pose as a JSON datagram; empty: none");
  v.field("foxglove", foxglove,
          "host:port of a Foxglove WebSocket server showing the run (e.g. 0.0.0.0:8765); empty: "
          "none");
}

void LiveConfig::validate() const {
  requireInRange("lidar_port", lidar_port, 0, 65535, "");
  requireInRange("imu_port", imu_port, 0, 65535, "");
  requireNonNegative("idle_timeout_s", idle_timeout_s, "s");
  requireInRange("socket_buffer_mb", socket_buffer_mb, 0.1, 2048.0, "MB");
  requireInRange("max_queued_scans", max_queued_scans, 1, 10000, "");
  if (!pose_udp.empty() && !udpAddressPort(pose_udp))
    throw ConfigError("pose_udp",
                      "expected host:port (e.g. 127.0.0.1:9870), got '" + pose_udp + "'");
  if (!foxglove.empty() && !udpAddressPort(foxglove))
    throw ConfigError("foxglove", "expected host:port (e.g. 0.0.0.0:8765), got '" + foxglove + "'");
}

std::optional<std::pair<std::string, std::uint16_t>> udpAddressPort(const std::string& text) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) return std::nullopt;
  int port = 0;
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(text.data() + colon + 1, last, port);
  if (error != std::errc() || end != last || port <= 0 || port > 65535) return std::nullopt;
  return std::pair{text.substr(0, colon), static_cast<std::uint16_t>(port)};
}

}  // namespace taiga
