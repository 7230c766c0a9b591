#pragma once
// Helpers for the Ouster decoder tests: fixture paths, the datagrams of a capture, and MD5 (to
// compare with the vendor's *_digest.json files).

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "taiga/io/ouster/pcap_reader.hpp"
#include "../../support/md5.hpp"

namespace taiga::test {

/// The Ouster fixtures, relative to the project root (the tests' working directory).
inline std::filesystem::path ousterData(const std::string& name) {
  return std::filesystem::path("../shared/data/ouster") / name;
}

struct Datagram {
  std::uint16_t port = 0;
  std::vector<std::uint8_t> payload;
};

/// Every UDP datagram of a capture, in file order.
inline std::vector<Datagram> readDatagrams(const std::filesystem::path& pcap) {
  io::ouster::PcapReader reader(pcap);
  std::vector<Datagram> datagrams;
  while (auto d = reader.next())
    datagrams.push_back({d->destination_port, {d->payload.begin(), d->payload.end()}});
  return datagrams;
}

/// The payloads of the datagrams of `size` bytes.
inline std::vector<std::vector<std::uint8_t>> payloadsOfSize(const std::filesystem::path& pcap,
                                                             std::size_t size) {
  std::vector<std::vector<std::uint8_t>> payloads;
  for (Datagram& d : readDatagrams(pcap))
    if (d.payload.size() == size) payloads.push_back(std::move(d.payload));
  return payloads;
}

inline std::vector<std::uint8_t> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void writeBytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

/// Appends `value` little endian in `bytes` bytes.
inline void putLe(std::vector<std::uint8_t>& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}


}  // namespace taiga::test
