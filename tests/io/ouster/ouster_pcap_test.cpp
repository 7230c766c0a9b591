// Capture files: link types and protocols built byte by byte, and damaged copies of a real
// capture (truncated, corrupt, not a capture).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../../support/temp_dir.hpp"
#include "ouster_test_support.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/capture.hpp"
#include "taiga/io/ouster/pcap_reader.hpp"

namespace taiga::io::ouster {
namespace {

using test::messageOf;
using test::ousterData;
using test::putLe;
using ::testing::HasSubstr;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t kEthernet = 1, kRaw = 101, kSll = 113, kSll2 = 276;

void putBe(Bytes& out, std::uint32_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

Bytes fileHeader(std::uint32_t link_type) {
  Bytes b;
  putLe(b, 0xA1B2C3D4, 4);  // microsecond timestamps
  putLe(b, 2, 2);
  putLe(b, 4, 2);
  putLe(b, 0, 8);
  putLe(b, 65535, 4);  // snaplen
  putLe(b, link_type, 4);
  return b;
}

void addRecord(Bytes& file, const Bytes& frame, std::size_t captured, std::uint32_t t_us) {
  putLe(file, 1700000000, 4);
  putLe(file, t_us, 4);
  putLe(file, captured, 4);
  putLe(file, frame.size(), 4);
  file.insert(file.end(), frame.begin(), frame.begin() + static_cast<std::ptrdiff_t>(captured));
}
void addRecord(Bytes& file, const Bytes& frame, std::uint32_t t_us = 0) {
  addRecord(file, frame, frame.size(), t_us);
}

Bytes udp(std::uint16_t port, const Bytes& payload) {
  Bytes b;
  putBe(b, 40000, 2);
  putBe(b, port, 2);
  putBe(b, static_cast<std::uint32_t>(payload.size() + 8), 2);
  putBe(b, 0, 2);
  b.insert(b.end(), payload.begin(), payload.end());
  return b;
}

Bytes ipv4(const Bytes& l4, std::uint8_t protocol = 17, std::uint16_t fragment = 0) {
  Bytes b{0x45, 0};
  putBe(b, static_cast<std::uint32_t>(l4.size() + 20), 2);
  putBe(b, 0, 2);
  putBe(b, fragment, 2);
  b.push_back(64);
  b.push_back(protocol);
  putBe(b, 0, 2);
  putBe(b, 0xA9FE0001, 4);
  putBe(b, 0xA9FE0002, 4);
  b.insert(b.end(), l4.begin(), l4.end());
  return b;
}

Bytes ipv6(const Bytes& l4, std::uint8_t next_header = 17) {
  Bytes b{0x60, 0, 0, 0};
  putBe(b, static_cast<std::uint32_t>(l4.size()), 2);
  b.push_back(next_header);
  b.push_back(64);
  b.resize(40, 0xFE);
  b.insert(b.end(), l4.begin(), l4.end());
  return b;
}

Bytes ethernet(std::uint16_t type, const Bytes& l3, bool vlan = false) {
  Bytes b(12, 0x11);
  if (vlan) {
    putBe(b, 0x8100, 2);
    putBe(b, 42, 2);
  }
  putBe(b, type, 2);
  b.insert(b.end(), l3.begin(), l3.end());
  return b;
}

Bytes sll(std::uint16_t type, const Bytes& l3) {
  Bytes b(14, 0);
  putBe(b, type, 2);
  b.insert(b.end(), l3.begin(), l3.end());
  return b;
}

Bytes sll2(std::uint16_t type, const Bytes& l3) {
  Bytes b;
  putBe(b, type, 2);
  b.resize(20, 0);
  b.insert(b.end(), l3.begin(), l3.end());
  return b;
}

std::vector<UdpDatagram> readAll(PcapReader& reader, std::vector<Bytes>& payloads) {
  std::vector<UdpDatagram> out;
  while (auto d = reader.next()) {
    payloads.emplace_back(d->payload.begin(), d->payload.end());
    out.push_back(*d);
  }
  return out;
}

TEST(OusterPcap, ReadsUdpOverEveryLinkType) {
  test::TempDir dir;
  const Bytes payload{'o', 'u', 's', 't', 'e', 'r'};
  const std::vector<std::pair<std::uint32_t, Bytes>> cases{
      {kEthernet, ethernet(0x0800, ipv4(udp(7502, payload)))},
      {kEthernet, ethernet(0x0800, ipv4(udp(7502, payload)), /*vlan=*/true)},
      {kEthernet, ethernet(0x86DD, ipv6(udp(7502, payload)))},
      {kSll, sll(0x0800, ipv4(udp(7502, payload)))},
      {kSll2, sll2(0x86DD, ipv6(udp(7502, payload)))},
      {kRaw, ipv4(udp(7502, payload))},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(i);
    Bytes file = fileHeader(cases[i].first);
    addRecord(file, cases[i].second, 250);
    const auto path = dir.file("case" + std::to_string(i) + ".pcap");
    test::writeBytes(path, file);
    PcapReader reader(path);
    std::vector<Bytes> payloads;
    const auto datagrams = readAll(reader, payloads);
    ASSERT_EQ(datagrams.size(), 1u);
    EXPECT_EQ(datagrams[0].destination_port, 7502);
    EXPECT_EQ(datagrams[0].source_port, 40000);
    EXPECT_EQ(datagrams[0].capture_time_ns, 1700000000LL * 1'000'000'000 + 250'000);
    EXPECT_EQ(payloads[0], payload);
  }
}

TEST(OusterPcap, SkipsAndCountsWhatIsNotAWholeUdpDatagram) {
  test::TempDir dir;
  const Bytes payload(100, 7);
  Bytes file = fileHeader(kEthernet);
  addRecord(file, ethernet(0x0806, Bytes(28, 0)));                          // ARP
  addRecord(file, ethernet(0x0800, ipv4(Bytes(40, 0), /*protocol=*/6)));    // TCP
  addRecord(file, ethernet(0x0800, ipv4(udp(7502, payload), 17, 0x2000)));  // first fragment
  addRecord(file, ethernet(0x86DD, ipv6(Bytes(60, 0), /*fragment*/ 44)));
  const Bytes whole = ethernet(0x0800, ipv4(udp(7502, payload)));
  addRecord(file, whole, whole.size() - 10, 0);  // cut by the snaplen
  addRecord(file, Bytes(8, 0));                  // short frame
  addRecord(file, whole, 9);                     // the good one
  test::writeBytes(dir.file("mixed.pcap"), file);

  PcapReader reader(dir.file("mixed.pcap"));
  std::vector<Bytes> payloads;
  const auto datagrams = readAll(reader, payloads);
  ASSERT_EQ(datagrams.size(), 1u);
  EXPECT_EQ(payloads[0], payload);
  const PcapStats& s = reader.stats();
  EXPECT_EQ(s.records, 7u);
  EXPECT_EQ(s.not_udp, 2u);
  EXPECT_EQ(s.fragments, 2u);
  EXPECT_EQ(s.cut_by_snaplen, 1u);
  EXPECT_EQ(s.malformed, 1u);
  EXPECT_FALSE(s.truncated_at_end);
}

TEST(OusterPcap, ATruncatedCaptureKeepsEverythingBeforeTheCut) {
  test::TempDir dir;
  const auto original = test::readBytes(ousterData("OS-0-128-U1_v2.3.0_1024x10.pcap"));
  const Bytes half(original.begin(),
                   original.begin() + static_cast<std::ptrdiff_t>(original.size() / 2));
  const auto path = dir.file("cut.pcap");
  test::writeBytes(path, half);

  PcapReader reader(path);
  std::vector<Bytes> payloads;
  const auto datagrams = readAll(reader, payloads);
  EXPECT_TRUE(reader.stats().truncated_at_end);
  EXPECT_GT(datagrams.size(), 30u);
  EXPECT_LT(datagrams.size(), 74u);

  // The capture still opens and gives the columns it holds as an incomplete frame.
  OusterCapture capture =
      openOusterCaptureStreams(path, ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
  ASSERT_TRUE(capture.lidar);
  const auto frame = capture.lidar->nextFrame();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->frame_id, 1491u);
  EXPECT_FALSE(frame->complete());
  EXPECT_GT(frame->columns_received, 400);
  EXPECT_LT(frame->columns_received, 1024);
  EXPECT_FALSE(capture.lidar->nextFrame());
}

TEST(OusterPcap, DamagedFilesGiveErrorsNamingTheFile) {
  test::TempDir dir;
  const auto original = test::readBytes(ousterData("OS-0-128-U1_v2.3.0_1024x10.pcap"));

  const auto header_only = dir.file("header.pcap");
  test::writeBytes(header_only, Bytes(original.begin(), original.begin() + 10));
  EXPECT_THAT(messageOf<InputError>([&] { PcapReader reader(header_only); }),
              HasSubstr(header_only.string() + ": not a readable pcap capture"));

  const auto empty = dir.file("empty.pcap");
  test::writeBytes(empty, {});
  EXPECT_THAT(messageOf<InputError>([&] { PcapReader reader(empty); }),
              HasSubstr(empty.string() + ": not a readable pcap capture"));

  // The second record claims a capture length no pcap allows.
  Bytes corrupt = original;
  const std::size_t second_record = 24 + 16 + (corrupt[32] | corrupt[33] << 8 | corrupt[34] << 16);
  for (std::size_t i = 8; i < 12; ++i) corrupt[second_record + i] = 0xFF;
  const auto corrupt_path = dir.file("corrupt.pcap");
  test::writeBytes(corrupt_path, corrupt);
  PcapReader reader(corrupt_path);
  EXPECT_TRUE(reader.next());
  EXPECT_THAT(messageOf<InputError>([&] { reader.next(); }),
              HasSubstr(corrupt_path.string() + ": corrupt capture at record 2"));
  EXPECT_THAT(messageOf<InputError>([&] {
                openOusterCapture(corrupt_path, ousterData("OS-0-128-U1_v2.3.0_1024x10.json"));
              }),
              HasSubstr("corrupt.pcap: corrupt capture at record 2"));

  EXPECT_THAT(
      messageOf<InputError>([&] { PcapReader r(ousterData("OS-0-128-U1_v2.3.0_1024x10.json")); }),
      HasSubstr("OS-0-128-U1_v2.3.0_1024x10.json: not a readable pcap capture"));
  EXPECT_THAT(messageOf<InputError>([&] { PcapReader r(dir.file("missing.pcap")); }),
              HasSubstr("missing.pcap: cannot open: No such file or directory"));
  EXPECT_THAT(messageOf<InputError>([&] { PcapReader r(dir.path()); }),
              HasSubstr("is a directory, expected a pcap capture"));

  Bytes wifi = fileHeader(105);  // IEEE 802.11
  const auto wifi_path = dir.file("wifi.pcap");
  test::writeBytes(wifi_path, wifi);
  EXPECT_THAT(messageOf<InputError>([&] { PcapReader r(wifi_path); }),
              HasSubstr("wifi.pcap: link type 105 (IEEE802_11) is not supported"));
}

}  // namespace
}  // namespace taiga::io::ouster
