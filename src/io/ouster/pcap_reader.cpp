#include "taiga/io/ouster/pcap_reader.hpp"

#include <fmt/format.h>
#include <pcap/pcap.h>

#include <cstdio>
#include <string>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"

namespace taiga::io::ouster {
namespace {

constexpr std::uint16_t kEtherTypeIpv4 = 0x0800;
constexpr std::uint16_t kEtherTypeIpv6 = 0x86DD;
constexpr std::uint8_t kProtocolUdp = 17;
constexpr std::uint8_t kIpv6Fragment = 44;
constexpr std::size_t kUdpHeaderBytes = 8;
constexpr std::size_t kIpv6HeaderBytes = 40;
constexpr int kMaxVlanTags = 2;

std::uint16_t be16(const std::uint8_t* p) { return static_cast<std::uint16_t>((p[0] << 8) | p[1]); }

bool isVlanTag(std::uint16_t ether_type) {
  return ether_type == 0x8100 || ether_type == 0x88A8 || ether_type == 0x9100;
}

/// The network-layer protocol and its offset for one link-layer frame; false when the link
/// header is incomplete.
bool linkPayload(int link_type, const std::uint8_t* data, std::size_t size,
                 std::uint16_t& ether_type, std::size_t& offset) {
  switch (link_type) {
    case DLT_EN10MB:
      if (size < 14) return false;
      ether_type = be16(data + 12);
      offset = 14;
      for (int tag = 0; tag < kMaxVlanTags && isVlanTag(ether_type); ++tag) {
        if (size < offset + 4) return false;
        ether_type = be16(data + offset + 2);
        offset += 4;
      }
      return true;
    case DLT_LINUX_SLL:
      if (size < 16) return false;
      ether_type = be16(data + 14);
      offset = 16;
      return true;
    case DLT_LINUX_SLL2:
      if (size < 20) return false;
      ether_type = be16(data);
      offset = 20;
      return true;
    default:
      break;
  }
  // Raw IP and loopback: the IP version nibble tells the protocol.
  offset = (link_type == DLT_NULL || link_type == DLT_LOOP) ? 4 : 0;
  if (size <= offset) return false;
  const int version = data[offset] >> 4;
  ether_type = version == 4 ? kEtherTypeIpv4 : version == 6 ? kEtherTypeIpv6 : 0;
  return true;
}

bool supportedLinkType(int link_type) {
  return link_type == DLT_EN10MB || link_type == DLT_LINUX_SLL || link_type == DLT_LINUX_SLL2 ||
         link_type == DLT_RAW || link_type == DLT_IPV4 || link_type == DLT_IPV6 ||
         link_type == DLT_NULL || link_type == DLT_LOOP;
}

}  // namespace

PcapReader::PcapReader(const std::filesystem::path& path) : path_(path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(fmt::format("{}: cannot open: No such file or directory", name));
  if (std::filesystem::is_directory(path, ec))
    throw InputError(fmt::format("{}: is a directory, expected a pcap capture", name));
  char error[PCAP_ERRBUF_SIZE] = {};
  handle_ =
      pcap_open_offline_with_tstamp_precision(name.c_str(), PCAP_TSTAMP_PRECISION_NANO, error);
  if (handle_ == nullptr)
    throw InputError(fmt::format("{}: not a readable pcap capture: {}", name, error));
  link_type_ = pcap_datalink(handle_);
  if (!supportedLinkType(link_type_)) {
    const char* link_name = pcap_datalink_val_to_name(link_type_);
    pcap_close(handle_);
    handle_ = nullptr;
    throw InputError(fmt::format(
        "{}: link type {} ({}) is not supported; expected Ethernet, Linux cooked or raw IP", name,
        link_type_, link_name != nullptr ? link_name : "unknown"));
  }
}

PcapReader::~PcapReader() {
  if (handle_ != nullptr) pcap_close(handle_);
}

std::optional<UdpDatagram> PcapReader::next() {
  while (!ended_) {
    pcap_pkthdr* header = nullptr;
    const u_char* data = nullptr;
    const int result = pcap_next_ex(handle_, &header, &data);
    if (result == PCAP_ERROR_BREAK) {  // end of file
      ended_ = true;
      break;
    }
    if (result != 1) {
      std::FILE* file = pcap_file(handle_);
      if (file != nullptr && std::feof(file) != 0) {
        // The file ends inside a record: keep what came before.
        ended_ = true;
        stats_.truncated_at_end = true;
        logger().warn("{}: the capture ends inside record {} ({}); reading stops there",
                      path_.string(), stats_.records + 1, pcap_geterr(handle_));
        break;
      }
      throw InputError(fmt::format("{}: corrupt capture at record {}: {}", path_.string(),
                                   stats_.records + 1, pcap_geterr(handle_)));
    }
    ++stats_.records;
    const std::size_t size = header->caplen;

    std::uint16_t ether_type = 0;
    std::size_t ip = 0;
    if (!linkPayload(link_type_, data, size, ether_type, ip)) {
      ++stats_.malformed;
      continue;
    }
    std::size_t udp = 0;
    std::size_t ip_end = 0;
    if (ether_type == kEtherTypeIpv4) {
      if (size < ip + 20) {
        ++stats_.malformed;
        continue;
      }
      const std::size_t header_bytes = static_cast<std::size_t>(data[ip] & 0x0F) * 4;
      const std::size_t total = be16(data + ip + 2);
      if (header_bytes < 20 || total < header_bytes) {
        ++stats_.malformed;
        continue;
      }
      if (data[ip + 9] != kProtocolUdp) {
        ++stats_.not_udp;
        continue;
      }
      if ((be16(data + ip + 6) & 0x3FFF) != 0) {  // more-fragments flag or a fragment offset
        ++stats_.fragments;
        continue;
      }
      udp = ip + header_bytes;
      ip_end = ip + total;
    } else if (ether_type == kEtherTypeIpv6) {
      if (size < ip + kIpv6HeaderBytes) {
        ++stats_.malformed;
        continue;
      }
      const std::uint8_t next_header = data[ip + 6];
      if (next_header == kIpv6Fragment) {
        ++stats_.fragments;
        continue;
      }
      if (next_header != kProtocolUdp) {
        ++stats_.not_udp;
        continue;
      }
      udp = ip + kIpv6HeaderBytes;
      ip_end = udp + be16(data + ip + 4);
    } else {
      ++stats_.not_udp;
      continue;
    }
    if (size < udp + kUdpHeaderBytes) {
      ++stats_.cut_by_snaplen;
      continue;
    }
    const std::size_t udp_bytes = be16(data + udp + 4);
    if (udp_bytes < kUdpHeaderBytes || udp + udp_bytes > ip_end) {
      ++stats_.malformed;
      continue;
    }
    if (udp + udp_bytes > size) {
      ++stats_.cut_by_snaplen;
      continue;
    }
    ++stats_.datagrams;
    UdpDatagram datagram;
    datagram.source_port = be16(data + udp);
    datagram.destination_port = be16(data + udp + 2);
    // Nanosecond precision was requested at open, so tv_usec holds nanoseconds.
    datagram.capture_time_ns = static_cast<std::int64_t>(header->ts.tv_sec) * 1'000'000'000 +
                               static_cast<std::int64_t>(header->ts.tv_usec);
    datagram.payload =
        std::span<const std::uint8_t>(data + udp + kUdpHeaderBytes, udp_bytes - kUdpHeaderBytes);
    return datagram;
  }
  return std::nullopt;
}

}  // namespace taiga::io::ouster
