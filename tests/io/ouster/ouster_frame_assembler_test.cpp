// Frame assembly from packet buffers (as from a bag): completion, loss, reordering, duplicates,
// late packets and bad packets, on the packets of real captures.

#include <gtest/gtest.h>

#include <algorithm>

#include "ouster_test_support.hpp"
#include "taiga/io/ouster/frame_assembler.hpp"

namespace taiga::io::ouster {
namespace {

using test::ousterData;
using Packets = std::vector<std::vector<std::uint8_t>>;

struct Fixture {
  SensorInfo info;
  Packets packets;
};

Fixture load(const std::string& pcap, const std::string& json) {
  Fixture f{readSensorInfo(ousterData(json)), {}};
  f.packets = test::payloadsOfSize(ousterData(pcap), LidarPacketLayout::of(f.info).packet_bytes);
  return f;
}

Fixture os0() { return load("OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-0-128-U1_v2.3.0_1024x10.json"); }

std::vector<AssembledFrame> assemble(const Fixture& f, const Packets& packets,
                                     FrameAssemblerStats* stats = nullptr) {
  FrameAssembler assembler(f.info);
  for (const auto& p : packets) assembler.addPacket(p);
  assembler.finish();
  std::vector<AssembledFrame> frames;
  while (auto frame = assembler.nextFrame()) frames.push_back(std::move(*frame));
  if (stats != nullptr) *stats = assembler.stats();
  return frames;
}

TEST(OusterFrameAssembler, EmitsACompleteFrameWithoutWaitingForTheNextOne) {
  const Fixture f = os0();
  ASSERT_EQ(f.packets.size(), 64u);
  FrameAssembler assembler(f.info);
  for (std::size_t i = 0; i < f.packets.size(); ++i) {
    EXPECT_EQ(assembler.hasFrame(), false) << i;
    EXPECT_EQ(assembler.addPacket(f.packets[i]), PacketStatus::kOk);
  }
  ASSERT_TRUE(assembler.hasFrame());
  const auto frame = assembler.nextFrame();
  EXPECT_TRUE(frame->complete());
  EXPECT_EQ(frame->scan.index, 0u);
  EXPECT_EQ(assembler.stats().frames, 1u);
  EXPECT_EQ(assembler.stats().invalid_columns, 0u);
}

TEST(OusterFrameAssembler, LostPacketsGiveAnIncompleteFrameWithTheColumnsReceived) {
  const Fixture f = os0();
  Packets lossy = f.packets;
  lossy.erase(lossy.begin() + 10, lossy.begin() + 13);
  lossy.pop_back();
  FrameAssemblerStats stats;
  const auto frames = assemble(f, lossy, &stats);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_FALSE(frames[0].complete());
  EXPECT_EQ(frames[0].columns_received, 1024 - 4 * 16);
  EXPECT_EQ(stats.incomplete_frames, 1u);
  for (auto column : frames[0].scan.cloud_in_lidar.columns) {
    EXPECT_FALSE(column >= 160 && column < 208) << column;
    EXPECT_LT(column, 1008);
  }
}

TEST(OusterFrameAssembler, ReorderedPacketsStillGivePointsInTimeOrder) {
  const Fixture f = os0();
  Packets shuffled = f.packets;
  std::swap(shuffled[3], shuffled[40]);
  std::swap(shuffled[0], shuffled[63]);
  const auto in_order = assemble(f, f.packets);
  const auto reordered = assemble(f, shuffled);
  ASSERT_EQ(reordered.size(), 1u);
  const PointCloud& a = in_order[0].scan.cloud_in_lidar;
  const PointCloud& b = reordered[0].scan.cloud_in_lidar;
  EXPECT_TRUE(std::is_sorted(b.times_s.begin(), b.times_s.end()));
  EXPECT_EQ(a.times_s, b.times_s);
  EXPECT_EQ(a.columns, b.columns);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(in_order[0].scan.t_start_s, reordered[0].scan.t_start_s);
}

TEST(OusterFrameAssembler, DuplicateAndLatePacketsAreDroppedAndCounted) {
  const Fixture f = load("OS-1-128_v2.3.0_1024x10_lb_n3.pcap", "OS-1-128_v2.3.0_1024x10.json");
  ASSERT_EQ(f.packets.size(), 192u);
  Packets packets = f.packets;
  packets.insert(packets.begin() + 5, f.packets[4]);        // duplicate inside frame 1795
  packets.insert(packets.begin() + 65 + 2, f.packets[20]);  // frame 1795 again, inside 1796
  FrameAssemblerStats stats;
  const auto frames = assemble(f, packets, &stats);
  ASSERT_EQ(frames.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(frames[i].frame_id, 1795 + i);
    EXPECT_TRUE(frames[i].complete());
    EXPECT_EQ(frames[i].scan.index, i);
  }
  EXPECT_EQ(stats.duplicate_columns, 16u);
  // The straggler of frame 1795 neither cuts frame 1796 short nor starts a frame of its own.
  EXPECT_EQ(stats.late_columns, 16u);
  EXPECT_EQ(stats.frames, 3u);
}

TEST(OusterFrameAssembler, BadCrcDropsThePacketAndTheFrameStaysIncomplete) {
  const Fixture f = load("crc_test.pcap", "crc_test.json");
  ASSERT_EQ(f.packets.size(), 34u);
  Packets packets = f.packets;
  packets[7][100] ^= 0xFF;
  FrameAssemblerStats stats;
  const auto frames = assemble(f, packets, &stats);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].frame_id, 254u);
  EXPECT_EQ(frames[0].columns_received, 512 - 16);
  EXPECT_EQ(frames[1].frame_id, 255u);
  EXPECT_EQ(frames[1].columns_received, 32);
  EXPECT_EQ(stats.dropped[static_cast<std::size_t>(PacketStatus::kBadCrc)], 1u);
  EXPECT_EQ(stats.droppedPackets(), 1u);
  EXPECT_EQ(stats.incomplete_frames, 2u);
}

TEST(OusterFrameAssembler, LatePacketsOfAnEmittedFrameAreDropped) {
  const Fixture f = os0();
  FrameAssembler assembler(f.info);
  for (const auto& p : f.packets) assembler.addPacket(p);
  ASSERT_TRUE(assembler.hasFrame());   // complete, emitted
  assembler.addPacket(f.packets[10]);  // arrives after the frame was emitted
  assembler.finish();
  EXPECT_EQ(assembler.stats().late_columns, 16u);
  EXPECT_TRUE(assembler.nextFrame());
  EXPECT_FALSE(assembler.nextFrame());
}

TEST(OusterFrameAssembler, WindowedPacketsSkipTheColumnsOutsideTheWindow) {
  const Fixture f = load("windowed_frame1.pcap", "windowed_frame1_0.json");
  FrameAssemblerStats stats;
  const auto frames = assemble(f, f.packets, &stats);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(frames[0].complete());
  EXPECT_EQ(frames[0].columns_expected, 256);
  EXPECT_EQ(stats.invalid_columns, 17u * 16 - 256);  // column 0 and columns 257..271
}

}  // namespace
}  // namespace taiga::io::ouster
