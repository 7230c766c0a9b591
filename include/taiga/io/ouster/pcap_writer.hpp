#pragma once
// Writes UDP datagrams into a capture file (pcap, nanosecond timestamps, Ethernet + IPv4 + UDP
// headers, written with libpcap) as a packet capture on the sensor's network would hold them, so
// PcapReader, Wireshark and `taiga replay` read it like a real sensor's capture.

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

struct pcap;         // libpcap's handle (pcap_t)
struct pcap_dumper;  // libpcap's writer (pcap_dumper_t)

namespace taiga::io::ouster {

class PcapWriter {
 public:
  /// Creates `path`; throws InputError naming it when it cannot be written.
  explicit PcapWriter(const std::filesystem::path& path);
  ~PcapWriter();
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  /// One datagram from the sensor (192.168.1.100:`source_port`) to the host (192.168.1.1:
  /// `destination_port`), captured at `capture_time_ns` (ns since the Unix epoch).
  void write(std::int64_t capture_time_ns, std::uint16_t source_port,
             std::uint16_t destination_port, std::span<const std::uint8_t> payload);
  /// Flushes and closes the file (also done by the destructor); throws InputError on a write error.
  void close();

 private:
  std::filesystem::path path_;
  pcap* handle_ = nullptr;
  pcap_dumper* dumper_ = nullptr;
  std::vector<std::uint8_t> frame_;
  std::uint16_t ip_id_ = 0;
};

}  // namespace taiga::io::ouster
