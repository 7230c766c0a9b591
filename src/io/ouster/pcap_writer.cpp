#include "taiga/io/ouster/pcap_writer.hpp"

#include <fmt/format.h>
#include <pcap/pcap.h>

#include <cstdio>

#include "taiga/core/errors.hpp"

namespace taiga::io::ouster {
namespace {

constexpr std::size_t kEthernetBytes = 14, kIpv4Bytes = 20, kUdpBytes = 8;
constexpr std::size_t kHeadersBytes = kEthernetBytes + kIpv4Bytes + kUdpBytes;
constexpr int kSnapLength = 262144;
constexpr std::uint8_t kSensorIp[4] = {192, 168, 1, 100};
constexpr std::uint8_t kHostIp[4] = {192, 168, 1, 1};

void putBe16(std::uint8_t* at, std::size_t value) {
  at[0] = static_cast<std::uint8_t>(value >> 8);
  at[1] = static_cast<std::uint8_t>(value);
}

/// RFC 791 header checksum: one's complement of the one's complement sum of 16-bit words.
std::uint16_t ipv4Checksum(const std::uint8_t* header) {
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < kIpv4Bytes; i += 2) sum += (header[i] << 8) | header[i + 1];
  while (sum >> 16) sum = (sum & 0xFFFF) + (sum >> 16);
  return static_cast<std::uint16_t>(~sum);
}

}  // namespace

PcapWriter::PcapWriter(const std::filesystem::path& path) : path_(path) {
  handle_ =
      pcap_open_dead_with_tstamp_precision(DLT_EN10MB, kSnapLength, PCAP_TSTAMP_PRECISION_NANO);
  if (handle_ != nullptr) dumper_ = pcap_dump_open(handle_, path.c_str());
  if (dumper_ == nullptr) {
    const std::string why = handle_ != nullptr ? pcap_geterr(handle_) : "out of memory";
    if (handle_ != nullptr) pcap_close(handle_);
    throw InputError(fmt::format("{}: cannot write the capture: {}", path.string(), why));
  }
}

PcapWriter::~PcapWriter() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see the error
  }
}

void PcapWriter::write(std::int64_t capture_time_ns, std::uint16_t source_port,
                       std::uint16_t destination_port, std::span<const std::uint8_t> payload) {
  frame_.assign(kHeadersBytes, 0);
  std::uint8_t* eth = frame_.data();
  constexpr std::uint8_t kHostMac[6] = {0x02, 0, 0, 0, 0, 0x01};
  constexpr std::uint8_t kSensorMac[6] = {0xbc, 0x0f, 0xa7, 0, 0, 0x01};  // Ouster's OUI
  std::copy(kHostMac, kHostMac + 6, eth);
  std::copy(kSensorMac, kSensorMac + 6, eth + 6);
  putBe16(eth + 12, 0x0800);  // IPv4
  std::uint8_t* ip = eth + kEthernetBytes;
  ip[0] = 0x45;  // version 4, 5 words
  putBe16(ip + 2, kIpv4Bytes + kUdpBytes + payload.size());
  putBe16(ip + 4, ip_id_++);
  putBe16(ip + 6, 0x4000);  // don't fragment
  ip[8] = 64;               // TTL
  ip[9] = 17;               // UDP
  std::copy(kSensorIp, kSensorIp + 4, ip + 12);
  std::copy(kHostIp, kHostIp + 4, ip + 16);
  putBe16(ip + 10, ipv4Checksum(ip));
  std::uint8_t* udp = ip + kIpv4Bytes;
  putBe16(udp, source_port);
  putBe16(udp + 2, destination_port);
  putBe16(udp + 4, kUdpBytes + payload.size());  // checksum 0: not computed (allowed in IPv4)
  frame_.insert(frame_.end(), payload.begin(), payload.end());

  pcap_pkthdr header{};
  header.ts.tv_sec = static_cast<time_t>(capture_time_ns / 1'000'000'000);
  header.ts.tv_usec = static_cast<suseconds_t>(capture_time_ns % 1'000'000'000);  // ns: see open
  header.caplen = header.len = static_cast<bpf_u_int32>(frame_.size());
  pcap_dump(reinterpret_cast<u_char*>(dumper_), &header, frame_.data());
}

void PcapWriter::close() {
  if (dumper_ == nullptr) return;
  const bool failed = pcap_dump_flush(dumper_) != 0 || std::ferror(pcap_dump_file(dumper_)) != 0;
  pcap_dump_close(dumper_);
  pcap_close(handle_);
  dumper_ = nullptr;
  handle_ = nullptr;
  if (failed) throw InputError(fmt::format("{}: writing the capture failed", path_.string()));
}

}  // namespace taiga::io::ouster
