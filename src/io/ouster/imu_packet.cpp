#include "taiga/io/ouster/imu_packet.hpp"

#include <cmath>

#include "byte_reader.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::io::ouster {
namespace {

using detail::ByteReader;

constexpr std::uint16_t kImuPacketType = 2;
constexpr double kNsToS = 1e-9;

// LEGACY byte offsets (Ouster firmware user manual, "IMU Data Format").
constexpr std::size_t kLegacyGyroTime = 16;
constexpr std::size_t kLegacyAcceleration = 24;
constexpr std::size_t kLegacyAngularVelocity = 36;
// ACCEL32_GYRO32_NMEA offsets within one 36-byte measurement.
constexpr std::size_t kMeasurementStatus = 10;
constexpr std::size_t kMeasurementAcceleration = 12;
constexpr std::size_t kMeasurementAngularVelocity = 24;

Eigen::Vector3d vector3(ByteReader& r, std::size_t at) {
  return {r.f32(at), r.f32(at + 4), r.f32(at + 8)};
}

bool usable(const ImuSample& s) {
  return s.t_s > 0.0 && s.acceleration_imu_mps2.allFinite() &&
         s.angular_velocity_imu_radps.allFinite();
}

}  // namespace

ImuPacketDecoder::ImuPacketDecoder(const SensorInfo& info, const DecoderOptions& options)
    : layout_(ImuPacketLayout::of(info)),
      options_(options),
      verify_crc_(info.imu_profile != ImuProfile::kLegacy &&
                  ouster::verifiesCrc(info, options.crc)),
      expected_serial_(options.check_sensor_id ? info.serial_number : std::nullopt) {}

PacketStatus ImuPacketDecoder::decode(std::span<const std::uint8_t> bytes,
                                      std::vector<ImuSample>& samples, int* skipped_samples) const {
  samples.clear();
  if (options_.allow_trailing_byte && bytes.size() == layout_.packet_bytes + 1)
    bytes = bytes.first(layout_.packet_bytes);
  if (bytes.size() != layout_.packet_bytes) return PacketStatus::kWrongSize;
  ByteReader r(bytes);
  int skipped = 0;

  if (layout_.profile == ImuProfile::kLegacy) {
    ImuSample s;
    s.t_s = static_cast<double>(r.le<std::uint64_t>(kLegacyGyroTime)) * kNsToS;
    s.acceleration_imu_mps2 = vector3(r, kLegacyAcceleration) * kStandardGravity_mps2;
    s.angular_velocity_imu_radps = vector3(r, kLegacyAngularVelocity) * kRadPerDeg;
    if (usable(s)) {
      samples.push_back(s);
    } else {
      ++skipped;
    }
  } else {
    if (r.le<std::uint16_t>(0) != kImuPacketType) return PacketStatus::kWrongPacketType;
    if (verify_crc_) {
      const std::size_t crc_at = bytes.size() - sizeof(std::uint64_t);
      if (crc64(bytes.first(crc_at)) != r.le<std::uint64_t>(crc_at)) return PacketStatus::kBadCrc;
    }
    if (expected_serial_ && r.le<std::uint64_t>(7, 5) != *expected_serial_)
      return PacketStatus::kOtherSensor;
    for (int i = 0; i < layout_.measurements_per_packet; ++i) {
      const std::size_t at =
          layout_.measurements_offset + static_cast<std::size_t>(i) * layout_.measurement_bytes;
      if ((r.le<std::uint16_t>(at + kMeasurementStatus) & 1U) == 0) continue;  // not valid
      ImuSample s;
      s.t_s = static_cast<double>(r.le<std::uint64_t>(at)) * kNsToS;
      s.acceleration_imu_mps2 = vector3(r, at + kMeasurementAcceleration);
      s.angular_velocity_imu_radps = vector3(r, at + kMeasurementAngularVelocity);
      if (usable(s)) {
        samples.push_back(s);
      } else {
        ++skipped;
      }
    }
  }
  if (skipped_samples != nullptr) *skipped_samples = skipped;
  if (r.failed()) {  // unreachable after the size check
    samples.clear();
    return PacketStatus::kWrongSize;
  }
  return PacketStatus::kOk;
}

}  // namespace taiga::io::ouster
