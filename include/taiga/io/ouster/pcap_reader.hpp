#pragma once
// UDP datagrams from a capture file (pcap or pcapng, read with libpcap). Link types: Ethernet
// (with 802.1Q/802.1ad VLAN tags), Linux cooked (SLL, SLL2), raw IP and BSD loopback; IPv4 and
// IPv6 (without extension headers). IP fragments are not reassembled: they are skipped and
// counted (Ouster's 8 KB+ lidar datagrams arrive whole when the capturing interface has a large
// enough MTU, as in Ouster's own captures).
//
// A corrupt capture throws InputError naming the file. A capture cut off inside its last record
// (a recording that was killed or ran out of disk) ends there with a logged warning, keeping
// everything before it.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>

struct pcap;  // libpcap's handle (pcap_t)

namespace taiga::io::ouster {

struct UdpDatagram {
  std::uint16_t source_port = 0;
  std::uint16_t destination_port = 0;
  std::int64_t capture_time_ns = 0;       ///< host capture time, ns since the Unix epoch
  std::span<const std::uint8_t> payload;  ///< valid until the next call to next()
};

struct PcapStats {
  std::uint64_t records = 0;         ///< capture records read
  std::uint64_t datagrams = 0;       ///< UDP datagrams returned
  std::uint64_t not_udp = 0;         ///< other protocols (ARP, TCP, ...), skipped
  std::uint64_t fragments = 0;       ///< IP fragments, skipped
  std::uint64_t cut_by_snaplen = 0;  ///< records shorter than their datagram, skipped
  std::uint64_t malformed = 0;       ///< inconsistent IP/UDP headers, skipped
  bool truncated_at_end = false;     ///< the file ended inside a record
};

class PcapReader {
 public:
  /// Opens `path`; throws InputError when it is missing, not a capture, or of an unsupported
  /// link type.
  explicit PcapReader(const std::filesystem::path& path);
  ~PcapReader();
  PcapReader(const PcapReader&) = delete;
  PcapReader& operator=(const PcapReader&) = delete;

  /// The next UDP datagram, or nothing at the end of the capture. Throws InputError on a corrupt
  /// record.
  std::optional<UdpDatagram> next();

  const PcapStats& stats() const { return stats_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  pcap* handle_ = nullptr;
  int link_type_ = 0;
  bool ended_ = false;
  PcapStats stats_;
};

}  // namespace taiga::io::ouster
