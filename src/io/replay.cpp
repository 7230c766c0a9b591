#include "taiga/io/replay.hpp"

#include <fmt/format.h>

#include <chrono>
#include <map>
#include <thread>

#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/pcap_reader.hpp"
#include "taiga/io/udp_socket.hpp"

namespace taiga::io {

ReplayReport replayCapture(const std::filesystem::path& pcap, const ReplayOptions& options) {
  using Clock = std::chrono::steady_clock;
  ouster::PcapReader reader(pcap);
  std::map<int, UdpSocket> sockets;  // by destination port
  ReplayReport report;
  std::optional<std::int64_t> first_ns, last_ns;
  Clock::time_point wall_start;
  double first_sent_s = 0.0;  // capture time of the first datagram sent, from the first one
  while (const std::optional<ouster::UdpDatagram> d = reader.next()) {
    if (!first_ns) first_ns = d->capture_time_ns;
    const double t_s = 1e-9 * static_cast<double>(d->capture_time_ns - *first_ns);
    if (t_s < options.skip_s) continue;
    if (report.datagrams == 0) {
      first_sent_s = t_s;
      wall_start = Clock::now();
      report.start_unix_s =
          std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
      report.first_capture_s = 1e-9 * static_cast<double>(d->capture_time_ns);
    }
    if (options.rate > 0.0) {
      const auto due =
          wall_start + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>((t_s - first_sent_s) / options.rate));
      std::this_thread::sleep_until(due);
      report.max_late_ms =
          std::max(report.max_late_ms,
                   std::chrono::duration<double, std::milli>(Clock::now() - due).count());
    }
    const int port = d->destination_port + options.port_offset;
    if (port <= 0 || port > 65535)
      throw InputError(fmt::format("--port-offset {}: port {} + {} is not a UDP port",
                                   options.port_offset, d->destination_port, options.port_offset));
    auto it = sockets.find(port);
    if (it == sockets.end())
      it = sockets
               .emplace(port, UdpSocket::connected(options.host, static_cast<std::uint16_t>(port)))
               .first;
    if (!it->second.send(d->payload)) ++report.refused;
    ++report.datagrams;
    report.bytes += d->payload.size();
    last_ns = d->capture_time_ns;
  }
  if (report.datagrams > 0) {
    report.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
    report.capture_s = 1e-9 * static_cast<double>(*last_ns - *first_ns) - first_sent_s;
  }
  return report;
}

}  // namespace taiga::io
