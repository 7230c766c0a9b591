#include "taiga/io/ouster/capture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <vector>

#include "byte_reader.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"

namespace taiga::io::ouster {
namespace {

// Ouster's default ports, used to recognize lidar/IMU traffic when the metadata names none.
constexpr std::uint16_t kDefaultLidarPort = 7502;
constexpr std::uint16_t kDefaultImuPort = 7503;
constexpr std::size_t kListedSizes = 6;

struct PortTraffic {
  std::map<std::size_t, std::uint64_t> sizes;  ///< datagram size -> count
  std::vector<std::uint8_t> first_lidar;       ///< first datagram of the lidar packet size
  std::vector<std::uint8_t> first_imu;         ///< first datagram of the IMU packet size
};

/// "port 7502: 64 x 12608 B, port 7503: 11 x 48 B" for messages.
std::string listTraffic(const std::map<std::uint16_t, PortTraffic>& traffic) {
  std::vector<std::tuple<std::uint64_t, std::uint16_t, std::size_t>> seen;
  for (const auto& [port, t] : traffic)
    for (const auto& [size, count] : t.sizes) seen.emplace_back(count, port, size);
  std::sort(seen.rbegin(), seen.rend());
  std::string text;
  for (std::size_t i = 0; i < seen.size() && i < kListedSizes; ++i) {
    const auto& [count, port, size] = seen[i];
    text += fmt::format("{}port {}: {} x {} bytes", i == 0 ? "" : ", ", port, count, size);
  }
  return text.empty() ? "no UDP datagrams" : text;
}

/// The port carrying packets of `size`: the metadata's port when it does, else the busiest one.
std::optional<std::uint16_t> choosePort(const std::map<std::uint16_t, PortTraffic>& traffic,
                                        std::size_t size, std::uint16_t metadata_port,
                                        std::uint64_t& count) {
  std::optional<std::uint16_t> best;
  count = 0;
  for (const auto& [port, t] : traffic) {
    const auto it = t.sizes.find(size);
    if (it == t.sizes.end()) continue;
    if (port == metadata_port) {
      count = it->second;
      return port;
    }
    if (it->second > count) {
      count = it->second;
      best = port;
    }
  }
  return best;
}

bool hasTrafficOn(const std::map<std::uint16_t, PortTraffic>& traffic, std::uint16_t port) {
  return port != 0 && traffic.contains(port);
}

/// Serial number and init id of a non-LEGACY packet header.
void checkIdentity(std::span<const std::uint8_t> packet, const SensorInfo& info,
                   const std::string& pcap_name, const std::string& metadata_name,
                   const char* kind) {
  detail::ByteReader r(packet);
  const auto init_id = r.le<std::uint32_t>(4, 3);
  const auto serial = r.le<std::uint64_t>(7, 5);
  if (info.serial_number && serial != *info.serial_number) {
    throw InputError(fmt::format(
        "{}: {} packets come from sensor serial {} (init id {}), but {} describes sensor serial "
        "{}: the metadata belongs to another sensor",
        pcap_name, kind, serial, init_id, metadata_name, *info.serial_number));
  }
  if (info.initialization_id && init_id != *info.initialization_id) {
    logger().warn(
        "{}: {} packets have init id {}, {} has {}: the sensor was re-initialized after the "
        "metadata was saved, so its configuration may differ",
        pcap_name, kind, init_id, metadata_name, *info.initialization_id);
  }
}

}  // namespace

CaptureProbe probeCapture(const std::filesystem::path& pcap, const SensorInfo& info,
                          const std::string& metadata_name, const CaptureOptions& options) {
  const std::string pcap_name = pcap.string();
  const bool want_lidar = info.lidar_profile != LidarProfile::kOff;
  const bool want_imu = info.imu_profile != ImuProfile::kOff;
  const std::size_t lidar_bytes = want_lidar ? LidarPacketLayout::of(info).packet_bytes : 0;
  const std::size_t imu_bytes = want_imu ? ImuPacketLayout::of(info).packet_bytes : 0;

  PcapReader reader(pcap);
  std::map<std::uint16_t, PortTraffic> traffic;
  CaptureProbe probe;
  while (probe.datagrams < options.probe_datagrams) {
    const std::optional<UdpDatagram> d = reader.next();
    if (!d) break;
    ++probe.datagrams;
    PortTraffic& t = traffic[d->destination_port];
    ++t.sizes[d->payload.size()];
    if (d->payload.size() == lidar_bytes && t.first_lidar.empty())
      t.first_lidar.assign(d->payload.begin(), d->payload.end());
    if (d->payload.size() == imu_bytes && t.first_imu.empty())
      t.first_imu.assign(d->payload.begin(), d->payload.end());
  }
  const std::string seen = listTraffic(traffic);
  const PcapStats& stats = reader.stats();
  const std::string skipped =
      stats.fragments > 0
          ? fmt::format(" ({} IP fragments were skipped: fragmented datagrams are not reassembled)",
                        stats.fragments)
          : "";

  if (want_lidar)
    probe.lidar_port = choosePort(traffic, lidar_bytes, info.udp_port_lidar, probe.lidar_packets);
  if (want_imu)
    probe.imu_port = choosePort(traffic, imu_bytes, info.udp_port_imu, probe.imu_packets);

  if (!probe.lidar_port && !probe.imu_port) {
    throw InputError(fmt::format(
        "{}: no datagram has the size of the packets that {} describes (lidar {} bytes: {}, {} "
        "columns x {} pixels; IMU {} bytes: {}); seen: {}{}. The metadata probably belongs to "
        "another sensor or configuration",
        pcap_name, metadata_name, lidar_bytes, info.lidar_profile_name, info.columns_per_packet,
        info.pixels_per_column, imu_bytes, info.imu_profile_name, seen, skipped));
  }
  const std::uint16_t lidar_port =
      info.udp_port_lidar != 0 ? info.udp_port_lidar : kDefaultLidarPort;
  if (want_lidar && !probe.lidar_port && hasTrafficOn(traffic, lidar_port)) {
    throw InputError(fmt::format(
        "{}: no lidar packet of the {} bytes that {} implies ({}, {} columns x {} pixels) although "
        "port {} carries traffic; seen: {}{}. The metadata probably belongs to another sensor or "
        "configuration",
        pcap_name, lidar_bytes, metadata_name, info.lidar_profile_name, info.columns_per_packet,
        info.pixels_per_column, lidar_port, seen, skipped));
  }
  const std::uint16_t imu_port = info.udp_port_imu != 0 ? info.udp_port_imu : kDefaultImuPort;
  if (want_imu && !probe.imu_port && hasTrafficOn(traffic, imu_port)) {
    throw InputError(fmt::format(
        "{}: no IMU packet of the {} bytes that {} implies ({}) although port {} carries traffic; "
        "seen: {}. The metadata probably belongs to another sensor or configuration",
        pcap_name, imu_bytes, metadata_name, info.imu_profile_name, imu_port, seen));
  }
  if (probe.lidar_port && info.lidar_profile != LidarProfile::kLegacy)
    checkIdentity(traffic[*probe.lidar_port].first_lidar, info, pcap_name, metadata_name, "lidar");
  if (probe.imu_port && info.imu_profile != ImuProfile::kLegacy)
    checkIdentity(traffic[*probe.imu_port].first_imu, info, pcap_name, metadata_name, "IMU");

  for (auto [found, expected, kind] : {std::tuple{probe.lidar_port, info.udp_port_lidar, "lidar"},
                                       std::tuple{probe.imu_port, info.udp_port_imu, "IMU"}}) {
    if (found && expected != 0 && *found != expected) {
      logger().info("{}: {} packets arrive on port {}, not on port {} that {} names", pcap_name,
                    kind, *found, expected, metadata_name);
    }
  }
  if (want_lidar && !probe.lidar_port)
    logger().info("{}: no lidar packets in the first {} datagrams", pcap_name, probe.datagrams);
  return probe;
}

OusterCapture openOusterCaptureStreams(const std::filesystem::path& pcap,
                                       const std::filesystem::path& metadata_json,
                                       const CaptureOptions& options) {
  OusterCapture capture;
  capture.info = readSensorInfo(metadata_json);
  capture.probe = probeCapture(pcap, capture.info, metadata_json.string(), options);
  const CaptureProbe& p = capture.probe;
  // When both streams share a port, each ignores the other's packet size.
  const bool shared = p.lidar_port && p.imu_port && *p.lidar_port == *p.imu_port;
  if (p.lidar_port) {
    std::optional<std::size_t> ignore;
    if (shared) ignore = ImuPacketLayout::of(capture.info).packet_bytes;
    capture.lidar = std::make_unique<OusterLidarSource>(
        fmt::format("{} (lidar)", pcap.string()),
        std::make_unique<PcapPortSource>(pcap, *p.lidar_port, ignore), capture.info,
        options.decoder);
  }
  if (p.imu_port) {
    std::optional<std::size_t> ignore;
    if (shared) ignore = LidarPacketLayout::of(capture.info).packet_bytes;
    capture.imu = std::make_unique<OusterImuSource>(
        fmt::format("{} (IMU)", pcap.string()),
        std::make_unique<PcapPortSource>(pcap, *p.imu_port, ignore), capture.info, options.decoder);
  }
  return capture;
}

std::vector<std::unique_ptr<StreamSource>> openOusterCapture(
    const std::filesystem::path& pcap, const std::filesystem::path& metadata_json,
    const CaptureOptions& options) {
  OusterCapture capture = openOusterCaptureStreams(pcap, metadata_json, options);
  std::vector<std::unique_ptr<StreamSource>> streams;
  if (capture.lidar) streams.push_back(std::move(capture.lidar));
  if (capture.imu) streams.push_back(std::move(capture.imu));
  return streams;
}

}  // namespace taiga::io::ouster
