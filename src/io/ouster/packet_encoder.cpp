#include "taiga/io/ouster/packet_encoder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/ouster/imu_packet.hpp"

namespace taiga::io::ouster {
namespace {

constexpr std::uint16_t kLidarPacketType = 1;
constexpr std::uint16_t kImuPacketType = 2;
constexpr std::size_t kHeaderBytes = 32;
constexpr std::size_t kNmeaBlockBytes = 100;
constexpr std::uint32_t kRange19Max_mm = 0x7FFFF;
constexpr std::uint32_t kRange20Max_mm = 0xFFFFF;
constexpr std::uint32_t kRange15Max_units = 0x7FFF;
constexpr int kRange15Unit_mm = 8;

std::uint64_t nanoseconds(double t_s) {
  return static_cast<std::uint64_t>(std::llround(t_s * 1e9));
}

/// Little-endian writes into a packet of fixed size.
class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& bytes) : bytes_(bytes) {}
  void le(std::size_t at, std::uint64_t value, std::size_t width) {
    for (std::size_t i = 0; i < width; ++i)
      bytes_.at(at + i) = static_cast<std::uint8_t>(value >> (8 * i));
  }
  void f32(std::size_t at, double value) {
    le(at, std::bit_cast<std::uint32_t>(static_cast<float>(value)), 4);
  }
  void vector3(std::size_t at, const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) f32(at + 4 * static_cast<std::size_t>(i), v[i]);
  }

 private:
  std::vector<std::uint8_t>& bytes_;
};

/// Packet header of the non-LEGACY profiles: type, frame id, init id, serial number.
void writeHeader(ByteWriter& w, std::uint16_t type, std::uint16_t frame_id,
                 const SensorInfo& info) {
  w.le(0, type, 2);
  w.le(2, frame_id, 2);
  w.le(4, info.initialization_id.value_or(0), 3);
  w.le(7, info.serial_number.value_or(0), 5);
}

/// The CRC-64 of everything before the last 8 bytes, in the last 8 bytes (firmware 3.x).
void writeCrc(std::vector<std::uint8_t>& bytes) {
  const std::size_t at = bytes.size() - sizeof(std::uint64_t);
  ByteWriter(bytes).le(at, crc64(std::span(bytes).first(at)), 8);
}

nlohmann::json transformMm(const lie::SE3& T) {
  Eigen::Matrix4d M = T.matrix();
  M.topRightCorner<3, 1>() *= 1e3;  // m -> mm
  std::vector<double> v;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v.push_back(M(r, c));
  return v;
}

}  // namespace

LidarPacketEncoder::LidarPacketEncoder(const SensorInfo& info)
    : info_(info), layout_(LidarPacketLayout::of(info)) {
  if (info.lidar_profile != LidarProfile::kLegacy &&
      info.lidar_profile != LidarProfile::kRng19Rfl8Sig16Nir16 &&
      info.lidar_profile != LidarProfile::kRng15Rfl8Nir8)
    throw InputError(
        fmt::format("{}: encoding lidar profile {} is not supported (LEGACY, "
                    "RNG19_RFL8_SIG16_NIR16, RNG15_RFL8_NIR8)",
                    info.source, info.lidar_profile_name));
  crc_ = info.lidar_profile != LidarProfile::kLegacy && verifiesCrc(info, CrcCheck::kAuto);
  for (int c = 0; c < info.columns_per_frame; ++c) {
    const double theta_e =
        2.0 * std::numbers::pi * (1.0 - static_cast<double>(c) / info.columns_per_frame);
    cos_encoder_.push_back(std::cos(theta_e));
    sin_encoder_.push_back(std::sin(theta_e));
  }
}

std::vector<EncodedPacket> LidarPacketEncoder::encode(const Scan& scan,
                                                      std::uint16_t frame_id) const {
  const auto columns = static_cast<std::size_t>(info_.columns_per_frame);
  const auto rows = static_cast<std::size_t>(info_.pixels_per_column);
  const PointCloud& cloud = scan.cloud_in_lidar;
  if (cloud.rings.size() != cloud.size() || cloud.columns.size() != cloud.size())
    throw std::invalid_argument("LidarPacketEncoder: the scan's points need rings and columns");

  // The sensor's grid: range (mm, 0 = no return) and reflectivity per pixel, time per column.
  std::vector<std::uint32_t> range_mm(columns * rows, 0);
  std::vector<std::uint8_t> reflectivity(columns * rows, 0);
  std::vector<double> column_t_s(columns, std::nan(""));
  const lie::SE3 T_lidar_sensor = info_.T_sensor_lidar.inverse();
  const Eigen::Vector3d beam_origin_mm = info_.T_lidar_beam.translation() * 1e3;
  const double beam_distance_mm = std::hypot(beam_origin_mm.x(), beam_origin_mm.z());
  const std::uint32_t max_mm = info_.lidar_profile == LidarProfile::kLegacy ? kRange20Max_mm
                               : info_.lidar_profile == LidarProfile::kRng15Rfl8Nir8
                                   ? kRange15Max_units * kRange15Unit_mm
                                   : kRange19Max_mm;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::size_t c = cloud.columns[i], row = cloud.rings[i];
    if (c >= columns || row >= rows)
      throw std::invalid_argument(fmt::format(
          "LidarPacketEncoder: point {} at column {} ring {} is outside the {} x {} grid", i, c,
          row, columns, rows));
    const Eigen::Vector3d p_lidar_mm = T_lidar_sensor * cloud.positions[i] * 1e3;
    const Eigen::Vector3d origin_mm(beam_origin_mm.x() * cos_encoder_[c],
                                    beam_origin_mm.x() * sin_encoder_[c], beam_origin_mm.z());
    const double r_mm = (p_lidar_mm - origin_mm).norm() + beam_distance_mm;
    const auto r = static_cast<std::uint32_t>(std::lround(r_mm));
    if (r == 0 || r > max_mm) continue;  // the sensor cannot report it
    range_mm[c * rows + row] = r;
    reflectivity[c * rows + row] = static_cast<std::uint8_t>(std::clamp(
        std::lround(i < cloud.intensities.size() ? cloud.intensities[i] : 0.0f), 0L, 255L));
    if (i < cloud.times_s.size() && std::isnan(column_t_s[c])) column_t_s[c] = cloud.times_s[i];
  }
  const double dt_s =
      columns > 1 ? (scan.t_end_s - scan.t_start_s) / static_cast<double>(columns - 1) : 0.0;
  for (std::size_t c = 0; c < columns; ++c)
    if (std::isnan(column_t_s[c])) column_t_s[c] = scan.t_start_s + static_cast<double>(c) * dt_s;

  const bool legacy = layout_.profile == LidarProfile::kLegacy;
  const auto per_packet = static_cast<std::size_t>(layout_.columns_per_packet);
  std::vector<EncodedPacket> packets;
  for (std::size_t first = 0; first < columns; first += per_packet) {
    const std::size_t end = std::min(columns, first + per_packet);
    if (std::all_of(range_mm.begin() + static_cast<std::ptrdiff_t>(first * rows),
                    range_mm.begin() + static_cast<std::ptrdiff_t>(end * rows),
                    [](std::uint32_t r) { return r == 0; }))
      continue;  // lost on the way (or all sky: indistinguishable here)
    EncodedPacket packet;
    packet.bytes.assign(layout_.packet_bytes, 0);
    ByteWriter w(packet.bytes);
    if (!legacy) writeHeader(w, kLidarPacketType, frame_id, info_);
    for (std::size_t k = 0; k < per_packet; ++k) {
      const std::size_t c = first + k;
      const std::size_t at = layout_.packet_header_bytes + k * layout_.column_bytes;
      if (c >= columns) continue;  // past the frame's last column: left invalid (status 0)
      packet.t_s = column_t_s[c];
      w.le(at, nanoseconds(column_t_s[c]), 8);
      w.le(at + 8, c, 2);
      if (legacy) {
        w.le(at + 10, frame_id, 2);
        w.le(at + 12, c * 90112 / columns, 4);  // encoder count: 90112 ticks per turn
        w.le(at + layout_.column_bytes - 4, 0xFFFFFFFFu, 4);
      } else {
        w.le(at + 10, 1, 2);  // status: valid
      }
      for (std::size_t row = 0; row < rows; ++row) {
        const std::size_t p = at + layout_.column_header_bytes + row * layout_.pixel_bytes;
        const std::uint32_t r = range_mm[c * rows + row];
        const std::uint8_t refl = reflectivity[c * rows + row];
        if (r == 0) continue;
        if (layout_.profile == LidarProfile::kRng15Rfl8Nir8) {
          w.le(p, (r + kRange15Unit_mm / 2) / kRange15Unit_mm, 2);
          w.le(p + 2, refl, 1);
        } else {
          w.le(p, r, 4);
          w.le(p + 4, refl, legacy ? 2 : 1);
          w.le(p + 6, refl, 2);  // signal: something non-zero for viewers
        }
      }
    }
    if (crc_) writeCrc(packet.bytes);
    packets.push_back(std::move(packet));
  }
  return packets;
}

EncodedPacket encodeImuPacket(const SensorInfo& info, std::span<const ImuSample> samples) {
  const ImuPacketLayout layout = ImuPacketLayout::of(info);
  EncodedPacket packet;
  packet.bytes.assign(layout.packet_bytes, 0);
  ByteWriter w(packet.bytes);
  if (samples.empty() || samples.size() > static_cast<std::size_t>(layout.measurements_per_packet))
    throw std::invalid_argument(fmt::format("encodeImuPacket: {} samples for a packet of {}",
                                            samples.size(), layout.measurements_per_packet));
  packet.t_s = samples.back().t_s;
  if (layout.profile == ImuProfile::kLegacy) {
    const ImuSample& s = samples.front();
    const std::uint64_t t_ns = nanoseconds(s.t_s);
    for (std::size_t at : {0, 8, 16}) w.le(at, t_ns, 8);  // system, accelerometer, gyroscope
    w.vector3(24, s.acceleration_imu_mps2 / kStandardGravity_mps2);
    w.vector3(36, s.angular_velocity_imu_radps * kDegPerRad);
    return packet;
  }
  writeHeader(w, kImuPacketType, 0, info);
  w.le(kHeaderBytes, nanoseconds(samples.front().t_s), 8);  // the NMEA block's time; no sentence
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::size_t at = layout.measurements_offset + i * layout.measurement_bytes;
    w.le(at, nanoseconds(samples[i].t_s), 8);
    w.le(at + 8, i, 2);
    w.le(at + 10, 1, 2);  // status: valid
    w.vector3(at + 12, samples[i].acceleration_imu_mps2);
    w.vector3(at + 24, samples[i].angular_velocity_imu_radps);
  }
  static_assert(kHeaderBytes + kNmeaBlockBytes == 132);
  if (verifiesCrc(info, CrcCheck::kAuto)) writeCrc(packet.bytes);
  return packet;
}

std::string sensorInfoJson(const SensorInfo& info) {
  using Json = nlohmann::json;
  const std::string lidar_mode =
      fmt::format("{}x{}", info.columns_per_frame, info.frames_per_second);
  const std::string lidar_profile(profileName(info.lidar_profile));
  const std::string imu_profile(profileName(info.imu_profile));
  Json root;
  root["beam_intrinsics"] = {
      {"beam_altitude_angles", info.beam_altitude_angles_deg},
      {"beam_azimuth_angles", info.beam_azimuth_angles_deg},
      {"lidar_origin_to_beam_origin_mm", info.lidar_origin_to_beam_origin_mm},
      {"beam_to_lidar_transform", transformMm(info.T_lidar_beam)}};
  root["lidar_intrinsics"] = {{"lidar_to_sensor_transform", transformMm(info.T_sensor_lidar)}};
  root["imu_intrinsics"] = {{"imu_to_sensor_transform", transformMm(info.T_sensor_imu)}};
  root["config_params"] = {
      {"lidar_mode", lidar_mode},          {"udp_port_lidar", info.udp_port_lidar},
      {"udp_port_imu", info.udp_port_imu}, {"udp_profile_lidar", lidar_profile},
      {"udp_profile_imu", imu_profile},    {"columns_per_packet", info.columns_per_packet}};
  root["lidar_data_format"] = {
      {"columns_per_frame", info.columns_per_frame},
      {"columns_per_packet", info.columns_per_packet},
      {"pixels_per_column", info.pixels_per_column},
      {"column_window", info.column_window},
      {"pixel_shift_by_row", info.pixel_shift_by_row.empty()
                                 ? std::vector<int>(info.beam_altitude_angles_deg.size(), 0)
                                 : info.pixel_shift_by_row},
      {"udp_profile_lidar", lidar_profile},
      {"udp_profile_imu", imu_profile},
      {"fps", info.frames_per_second}};
  root["imu_data_format"] = {{"imu_measurements_per_packet", info.imu_measurements_per_packet}};
  Json sensor = {
      {"prod_line", info.product_line},
      {"image_rev", info.firmware},
      {"build_rev", info.firmware_version
                        ? fmt::format("v{}.{}.{}", info.firmware_version->major,
                                      info.firmware_version->minor, info.firmware_version->patch)
                        : info.firmware}};
  if (info.serial_number) sensor["prod_sn"] = std::to_string(*info.serial_number);
  if (info.initialization_id) sensor["initialization_id"] = *info.initialization_id;
  root["sensor_info"] = sensor;
  return root.dump(2) + "\n";
}

}  // namespace taiga::io::ouster
