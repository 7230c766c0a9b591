// libFuzzer entry point for the Ouster decoders (built by scripts/fuzz.sh). The first byte picks
// what the rest feeds:
//   0     metadata JSON text -> parseSensorInfo, then the layouts and the geometry it allows;
//   1     UDP datagrams as a live sensor's socket delivers them (each a 2-byte length and the
//         bytes), sorted by size as the live receiver does, through the capture streams and the
//         time-ordered Recording;
//   2..   lidar packets of a small synthetic sensor of one profile (the input is cut into packets
//         of the profile's size, so decoding gets past the size check) -> FrameAssembler, and the
//         whole input as one IMU packet of each IMU profile.
// Every outcome but a crash, a sanitizer report or a hang is fine: bad input must give an
// InputError (metadata) or a dropped packet (packets).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/io/ouster/beam_geometry.hpp"
#include "taiga/io/ouster/capture.hpp"
#include "taiga/io/ouster/frame_assembler.hpp"
#include "taiga/io/ouster/imu_packet.hpp"
#include "taiga/io/ouster/live.hpp"

namespace {

using namespace taiga::io::ouster;

constexpr LidarProfile kProfiles[] = {LidarProfile::kLegacy,
                                      LidarProfile::kRng19Rfl8Sig16Nir16,
                                      LidarProfile::kRng15Rfl8Nir8,
                                      LidarProfile::kRng19Rfl8Sig16Nir16Dual,
                                      LidarProfile::kRng15Rfl8Nir8Dual,
                                      LidarProfile::kRng19Rfl8Sig16Nir16Zone16,
                                      LidarProfile::kRng15Rfl8Nir8Zone16};

/// 4 beams, 64 columns in 4-column packets: packets of at most a few hundred bytes.
SensorInfo smallSensor(LidarProfile profile, ImuProfile imu) {
  SensorInfo info;
  info.source = "fuzz";
  info.columns_per_frame = 64;
  info.columns_per_packet = 4;
  info.pixels_per_column = 4;
  info.frames_per_second = 10;
  info.column_window = {60, 5};  // wraps
  info.lidar_profile = profile;
  info.imu_profile = imu;
  info.imu_measurements_per_packet = 2;
  info.serial_number = 1234;
  info.beam_altitude_angles_deg = {10, 3, -3, -10};
  info.beam_azimuth_angles_deg = {3, 1, -1, -3};
  info.lidar_origin_to_beam_origin_mm = 15.8;
  return info;
}

void fuzzMetadata(std::string_view text) {
  try {
    const SensorInfo info = parseSensorInfo(text, "fuzz.json");
    const BeamGeometry geometry(info);
    (void)geometry.pointInSensor(0, 0, 1000);
    (void)LidarPacketLayout::of(info);
    (void)ImuPacketLayout::of(info);
  } catch (const taiga::InputError&) {
  }
}

void fuzzPackets(std::uint8_t selector, std::span<const std::uint8_t> bytes) {
  const LidarProfile profile = kProfiles[selector % std::size(kProfiles)];
  const SensorInfo info = smallSensor(profile, ImuProfile::kLegacy);
  FrameAssembler assembler(info, {.crc = (selector & 0x80) ? CrcCheck::kAlways : CrcCheck::kNever});
  const std::size_t size = assembler.decoder().layout().packet_bytes;
  for (std::size_t at = 0; at < bytes.size(); at += size)
    assembler.addPacket(bytes.subspan(at, std::min(size, bytes.size() - at)));
  assembler.finish();
  while (auto frame = assembler.nextFrame()) {
    if (!frame->scan.cloud_in_lidar.isConsistent()) __builtin_trap();
  }
  std::vector<taiga::ImuSample> samples;
  for (ImuProfile imu : {ImuProfile::kLegacy, ImuProfile::kAccel32Gyro32Nmea}) {
    const ImuPacketDecoder decoder(smallSensor(profile, imu), {.crc = CrcCheck::kNever});
    decoder.decode(bytes, samples);
    if (bytes.size() >= decoder.layout().packet_bytes)
      decoder.decode(bytes.first(decoder.layout().packet_bytes), samples);
  }
}

/// Datagrams from memory, as the live receiver's queue hands them over.
class Datagrams final : public DatagramSource {
 public:
  explicit Datagrams(std::vector<std::span<const std::uint8_t>> datagrams)
      : datagrams_(std::move(datagrams)) {}
  std::optional<std::span<const std::uint8_t>> next() override {
    if (next_ == datagrams_.size()) return std::nullopt;
    return datagrams_[next_++];
  }

 private:
  std::vector<std::span<const std::uint8_t>> datagrams_;
  std::size_t next_ = 0;
};

void fuzzLiveDatagrams(std::span<const std::uint8_t> bytes) {
  const SensorInfo info = smallSensor(LidarProfile::kRng19Rfl8Sig16Nir16, ImuProfile::kLegacy);
  const std::size_t lidar_bytes = LidarPacketLayout::of(info).packet_bytes;
  const std::size_t imu_bytes = ImuPacketLayout::of(info).packet_bytes;
  std::vector<std::span<const std::uint8_t>> lidar, imu;
  for (std::size_t at = 0; at + 2 <= bytes.size();) {
    const std::size_t size =
        std::min<std::size_t>(bytes[at] | (bytes[at + 1] << 8), bytes.size() - at - 2);
    const std::span<const std::uint8_t> datagram = bytes.subspan(at + 2, size);
    at += 2 + size;
    switch (classifyDatagram(datagram.size(), lidar_bytes, imu_bytes)) {
      case DatagramKind::kLidar:
        lidar.push_back(datagram);
        break;
      case DatagramKind::kImu:
        imu.push_back(datagram);
        break;
      case DatagramKind::kOther:
        break;
    }
  }
  std::vector<std::unique_ptr<taiga::io::StreamSource>> streams;
  streams.push_back(std::make_unique<OusterLidarSource>(
      "fuzz (lidar)", std::make_unique<Datagrams>(std::move(lidar)), info, DecoderOptions{}));
  streams.push_back(std::make_unique<OusterImuSource>(
      "fuzz (IMU)", std::make_unique<Datagrams>(std::move(imu)), info, DecoderOptions{}));
  taiga::io::Recording recording("fuzz", std::move(streams));
  try {
    while (auto event = recording.next()) {
      const auto* scan = std::get_if<taiga::io::Scan>(&*event);
      if (scan != nullptr && !scan->cloud_in_lidar.isConsistent()) __builtin_trap();
    }
  } catch (const taiga::InputError&) {  // a sensor clock that jumps back by more than 1 s
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = [] {
    taiga::setLogLevel(spdlog::level::off);
    return true;
  }();
  (void)quiet;
  if (size == 0) return 0;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  if (data[0] == 0) {
    fuzzMetadata({reinterpret_cast<const char*>(rest.data()), rest.size()});
  } else if (data[0] == 1) {
    fuzzLiveDatagrams(rest);
  } else {
    fuzzPackets(data[0], rest);
  }
  return 0;
}
