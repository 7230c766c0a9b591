#pragma once
// `taiga replay`: a capture file's UDP datagrams sent again, to their recorded destination ports
// on another host (or this one), at their recorded pace or faster: a sensor on the bench, for
// `taiga run --live`, demos and tests.

#include <cstdint>
#include <filesystem>
#include <string>

namespace taiga::io {

struct ReplayOptions {
  std::string host = "127.0.0.1";
  double rate = 1.0;    ///< x the recorded pace; 0: as fast as the machine sends
  int port_offset = 0;  ///< added to every destination port
  double skip_s = 0.0;  ///< start this far into the capture
};

struct ReplayReport {
  std::uint64_t datagrams = 0;
  std::uint64_t bytes = 0;
  std::uint64_t refused = 0;  ///< sends the system refused (e.g. nobody listening on loopback)
  double capture_s = 0.0;     ///< capture time spanned by the datagrams sent
  double wall_s = 0.0;
  double max_late_ms = 0.0;  ///< the latest a datagram left after its due time
  /// When the first datagram was sent (Unix time, s) and its capture time (s): a datagram of
  /// capture time t was due at start_unix_s + (t - first_capture_s) / rate, for latency checks.
  double start_unix_s = 0.0, first_capture_s = 0.0;
};

/// Sends every UDP datagram of `pcap` (pcap_reader.hpp's formats); InputError for an unreadable
/// capture or an unresolvable host.
ReplayReport replayCapture(const std::filesystem::path& pcap, const ReplayOptions& options);

}  // namespace taiga::io
