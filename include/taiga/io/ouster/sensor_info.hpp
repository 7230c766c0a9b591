#pragma once
// Ouster sensor metadata: the JSON the sensor reports (GET /api/v1/sensor/metadata, or the
// get_* TCP commands of firmware 1.x), as saved next to a capture by the Ouster SDK, ouster-ros or
// Ouster Studio. Decoded without the vendor SDK.
//
// Two layouts exist and both are read:
// - legacy (flat): beam_altitude_angles, lidar_mode, data_format{...}, lidar_to_sensor_transform,
//   prod_line, ... at the top level (firmware 1.12 to 2.x clients, "*_legacy.json");
// - current (nested): beam_intrinsics{...}, lidar_data_format{...}, config_params{...},
//   sensor_info{...}, lidar_intrinsics{...}, imu_intrinsics{...}, imu_data_format{...}.
// Firmware that predates a field gets Ouster's documented default (see docs/ouster.md); every such
// default is listed in SensorInfo::defaulted_fields. An Ouster Studio "reduced config" (only the
// beam angles and lidar_mode) is accepted with defaults for a gen-1 OS-1 and a logged warning.
//
// Bad or missing required fields throw InputError("FILE: field 'a.b': expected ..., found ...").

#include <array>
#include <compare>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace taiga::io::ouster {

/// udp_profile_lidar: the layout of a lidar packet's channel data (Ouster firmware user manual,
/// "Lidar Data Format"). kOther is a profile this decoder does not know; the metadata still reads,
/// but its lidar packets cannot be decoded.
enum class LidarProfile {
  kLegacy,                     ///< firmware < 2.2 layout, 12-byte pixels, 16-byte column headers
  kRng19Rfl8Sig16Nir16,        ///< single return, 12-byte pixels
  kRng15Rfl8Nir8,              ///< low data rate, 4-byte pixels, range in 8 mm units
  kRng19Rfl8Sig16Nir16Dual,    ///< dual return, 16-byte pixels
  kRng15Rfl8Nir8Dual,          ///< low data rate dual return, 8-byte pixels
  kRng19Rfl8Sig16Nir16Zone16,  ///< zone monitoring, 12-byte pixels
  kRng15Rfl8Nir8Zone16,        ///< zone monitoring, low data rate, 8-byte pixels
  kOff,                        ///< the sensor sends no lidar packets
  kOther,
};

/// udp_profile_imu (Ouster firmware user manual, "IMU Data Format").
enum class ImuProfile {
  kLegacy,             ///< 48-byte packets, one sample, acceleration in g, angular rate in deg/s
  kAccel32Gyro32Nmea,  ///< firmware >= 3.2: header, NMEA block, N samples in m/s^2 and rad/s
  kOff,
  kOther,
};

struct FirmwareVersion {
  int major = 0;
  int minor = 0;
  int patch = 0;
  auto operator<=>(const FirmwareVersion&) const = default;
};

struct SensorInfo {
  std::string source;           ///< the file (or name) the metadata came from, for messages
  bool legacy_layout = false;   ///< flat legacy JSON rather than the nested current layout
  bool reduced_config = false;  ///< only beam angles and lidar_mode were given
  /// "a.b" names of fields that were absent and got Ouster's default value.
  std::vector<std::string> defaulted_fields;

  // Identity (empty / nullopt when the file does not say).
  std::string product_line;                         ///< e.g. "OS-0-128"
  std::optional<std::uint64_t> serial_number;       ///< prod_sn
  std::optional<std::uint32_t> initialization_id;   ///< changes at every sensor (re)initialization
  std::string firmware;                             ///< image_rev, else build_rev, as reported
  std::optional<FirmwareVersion> firmware_version;  ///< parsed from `firmware`, e.g. 2.3.0

  // Data format.
  std::string lidar_mode;     ///< e.g. "1024x10"
  int columns_per_frame = 0;  ///< measurement ids run 0 .. columns_per_frame - 1
  int columns_per_packet = 16;
  int pixels_per_column = 0;  ///< beams (rows)
  int frames_per_second = 0;
  /// First and last measurement id the sensor fires, inclusive; first > last when the window
  /// wraps through measurement id 0 (e.g. [370, 85] of 512).
  std::array<int, 2> column_window{0, 0};
  std::vector<int> pixel_shift_by_row;  ///< for destaggering images; unused for points
  LidarProfile lidar_profile = LidarProfile::kLegacy;
  std::string lidar_profile_name = "LEGACY";
  ImuProfile imu_profile = ImuProfile::kLegacy;
  std::string imu_profile_name = "LEGACY";
  int imu_measurements_per_packet = 1;   ///< 1 for LEGACY
  std::string header_type = "STANDARD";  ///< packet header layout; FUSA is not decoded

  // Intrinsics (Ouster firmware user manual, "Coordinate Frames and XYZ Calculation").
  std::vector<double> beam_altitude_angles_deg;  ///< one per row, + up
  std::vector<double> beam_azimuth_angles_deg;   ///< one per row, offset from the column angle
  double lidar_origin_to_beam_origin_mm = 0.0;
  /// Beam origin in the lidar frame (translation in m; x = lidar_origin_to_beam_origin_mm,
  /// z = beam origin height for firmware >= 2.5 beam_to_lidar_transform).
  lie::SE3 T_lidar_beam;
  lie::SE3 T_sensor_lidar;  ///< lidar_to_sensor_transform, translation in m
  lie::SE3 T_sensor_imu;    ///< imu_to_sensor_transform, translation in m

  // Network (0 when the file does not say).
  std::uint16_t udp_port_lidar = 0;
  std::uint16_t udp_port_imu = 0;

  /// Number of measurement ids inside column_window (the columns a complete frame carries).
  int windowColumns() const;
  /// True when `measurement_id` lies inside column_window.
  bool inWindow(int measurement_id) const;
};

/// Reads and validates a metadata file. Throws InputError naming the file and the field.
SensorInfo readSensorInfo(const std::filesystem::path& json_path);

/// Parses metadata text; `source_name` stands for the file in messages (e.g. a bag topic).
SensorInfo parseSensorInfo(std::string_view json_text, std::string_view source_name);

/// The JSON spelling of a profile ("RNG15_RFL8_NIR8", ...).
std::string_view profileName(LidarProfile profile);
std::string_view profileName(ImuProfile profile);

}  // namespace taiga::io::ouster
