#include "ouster_capture_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "taiga/core/errors.hpp"

namespace taiga::sim::detail {
namespace {

constexpr std::uint16_t kLidarPort = 7502;  // Ouster's defaults
constexpr std::uint16_t kImuPort = 7503;
constexpr std::uint64_t kFirstSerial = 990000000000;       // < 2^40, as the header's 40 bits need
constexpr io::ouster::FirmwareVersion kFirmware{3, 1, 0};  // packet footers carry the CRC-64

std::int64_t nanoseconds(double t_s) { return std::llround(t_s * 1e9); }

}  // namespace

io::ouster::SensorInfo simulatedSensorInfo(const LidarParams& params, const LidarGeometry& geometry,
                                           const std::string& lidar_profile, std::uint64_t seed) {
  using namespace io::ouster;
  if (params.metadata_json.empty() && params.model != "os0-128")
    throw InputError(fmt::format(
        "--pcap: lidar.model {} is not an Ouster sensor; Ouster captures need lidar.model "
        "os0-128 or lidar.metadata_json",
        params.model));
  const double fps = params.rotation_hz;
  if (std::abs(fps - std::round(fps)) > 1e-9)
    throw InputError(fmt::format(
        "--pcap: lidar.rotation_hz {} is not a whole number of frames per second", fps));
  SensorInfo info;
  info.source = "simulated sensor";
  const int rows = static_cast<int>(geometry.beam_altitude_deg.size());
  info.product_line = fmt::format("OS-0-{}", rows);
  info.serial_number = kFirstSerial + seed % 1000000;
  info.initialization_id = static_cast<std::uint32_t>(seed % (1u << 24));
  info.firmware = fmt::format("ousteros-image-prod-aries-v{}.{}.{}+taiga-simulate", kFirmware.major,
                              kFirmware.minor, kFirmware.patch);
  info.firmware_version = kFirmware;
  info.columns_per_frame = params.columns;
  info.columns_per_packet = 16;
  info.pixels_per_column = rows;
  info.frames_per_second = static_cast<int>(std::lround(fps));
  info.lidar_mode = fmt::format("{}x{}", info.columns_per_frame, info.frames_per_second);
  info.column_window = {0, params.columns - 1};
  info.lidar_profile_name = lidar_profile;
  info.lidar_profile = LidarProfile::kOther;
  for (LidarProfile p :
       {LidarProfile::kLegacy, LidarProfile::kRng19Rfl8Sig16Nir16, LidarProfile::kRng15Rfl8Nir8})
    if (profileName(p) == lidar_profile) info.lidar_profile = p;
  if (info.lidar_profile == LidarProfile::kOther)
    throw InputError(fmt::format(
        "--pcap: unknown lidar profile '{}' (LEGACY, RNG19_RFL8_SIG16_NIR16, RNG15_RFL8_NIR8)",
        lidar_profile));
  info.imu_profile = ImuProfile::kLegacy;
  info.imu_profile_name = "LEGACY";
  info.beam_altitude_angles_deg = geometry.beam_altitude_deg;
  info.beam_azimuth_angles_deg = geometry.beam_azimuth_deg;
  info.lidar_origin_to_beam_origin_mm = geometry.lidar_origin_to_beam_origin_m * 1e3;
  info.T_lidar_beam = lie::SE3(lie::SO3(), Eigen::Vector3d(geometry.lidar_origin_to_beam_origin_m,
                                                           0.0, geometry.beam_origin_z_m));
  info.T_sensor_lidar = geometry.T_sensor_lidar;
  info.T_sensor_imu = geometry.T_sensor_imu;
  info.udp_port_lidar = kLidarPort;
  info.udp_port_imu = kImuPort;
  return info;
}

OusterCaptureWriter::OusterCaptureWriter(const std::filesystem::path& dir,
                                         io::ouster::SensorInfo info)
    : info_(std::move(info)), lidar_(info_), pcap_(dir / "capture.pcap") {
  std::ofstream json(dir / "capture.json");
  json << io::ouster::sensorInfoJson(info_);
  if (!json)
    throw InputError(fmt::format("{}: cannot write the metadata", (dir / "capture.json").string()));
}

void OusterCaptureWriter::writeImu(const ImuSample& sample, double capture_t_s) {
  queue_.push_back({capture_t_s, info_.udp_port_imu,
                    io::ouster::encodeImuPacket(info_, std::span(&sample, 1)).bytes});
}

void OusterCaptureWriter::writeScan(const io::Scan& scan, std::uint16_t frame_id,
                                    double capture_minus_stamp_s) {
  double last_t_s = -1e300;
  for (io::ouster::EncodedPacket& p : lidar_.encode(scan, frame_id)) {
    last_t_s = p.t_s + capture_minus_stamp_s;
    queue_.push_back({last_t_s, info_.udp_port_lidar, std::move(p.bytes)});
  }
  flushUntil(last_t_s);
}

void OusterCaptureWriter::flushUntil(double capture_t_s) {
  std::stable_sort(queue_.begin(), queue_.end(),
                   [](const Queued& a, const Queued& b) { return a.capture_t_s < b.capture_t_s; });
  const auto end = std::find_if(queue_.begin(), queue_.end(),
                                [&](const Queued& q) { return q.capture_t_s > capture_t_s; });
  for (auto it = queue_.begin(); it != end; ++it)
    pcap_.write(nanoseconds(it->capture_t_s), it->port, it->port, it->bytes);
  queue_.erase(queue_.begin(), end);
}

void OusterCaptureWriter::close() {
  flushUntil(1e300);
  pcap_.close();
}

}  // namespace taiga::sim::detail
