// libFuzzer entry point for the Ouster decoders (built by scripts/fuzz.sh). The first byte picks what the rest feeds:
//   0     metadata JSON text -> parseSensorInfo, then the layouts and the geometry it allows;
//   1..   lidar packets of a small synthetic sensor of one profile (the input is cut into packets
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
#include "taiga/io/ouster/frame_assembler.hpp"
#include "taiga/io/ouster/imu_packet.hpp"

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
  } else {
    fuzzPackets(data[0], rest);
  }
  return 0;
}
