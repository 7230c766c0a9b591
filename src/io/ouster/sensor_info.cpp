#include "taiga/io/ouster/sensor_info.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <utility>

#include "json_fields.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"

namespace taiga::io::ouster {
namespace {

using detail::Json;
using detail::JsonFields;
using detail::JsonSection;

constexpr std::array<std::pair<LidarProfile, std::string_view>, 8> kLidarProfiles{{
    {LidarProfile::kLegacy, "LEGACY"},
    {LidarProfile::kRng19Rfl8Sig16Nir16, "RNG19_RFL8_SIG16_NIR16"},
    {LidarProfile::kRng15Rfl8Nir8, "RNG15_RFL8_NIR8"},
    {LidarProfile::kRng19Rfl8Sig16Nir16Dual, "RNG19_RFL8_SIG16_NIR16_DUAL"},
    {LidarProfile::kRng15Rfl8Nir8Dual, "RNG15_RFL8_NIR8_DUAL"},
    {LidarProfile::kRng19Rfl8Sig16Nir16Zone16, "RNG19_RFL8_SIG16_NIR16_ZONE16"},
    {LidarProfile::kRng15Rfl8Nir8Zone16, "RNG15_RFL8_NIR8_ZONE16"},
    {LidarProfile::kOff, "OFF"},
}};
constexpr std::array<std::pair<ImuProfile, std::string_view>, 3> kImuProfiles{{
    {ImuProfile::kLegacy, "LEGACY"},
    {ImuProfile::kAccel32Gyro32Nmea, "ACCEL32_GYRO32_NMEA"},
    {ImuProfile::kOff, "OFF"},
}};

// Ouster's nominal beam origin offsets (the Ouster SDK's default_sensor_info()). The field came
// with firmware 1.14 (its betas lack it) and every 2.x file has it; metadata without it comes from
// gen-1 OS-1 units, whose value is 12.163 mm (sensor 991913000010 reports 12.163 once upgraded to
// 2.0, where the SDK's per-product default would say 15.806), so that is used for firmware before
// 2.0 and when the product line is unknown.
constexpr FirmwareVersion kFirstBeamOriginFirmware{2, 0, 0};
constexpr double kGenOneBeamOriginMm = 12.163;
double defaultBeamOriginMm(const SensorInfo& info) {
  if (info.firmware_version && *info.firmware_version < kFirstBeamOriginFirmware)
    return kGenOneBeamOriginMm;
  const std::string_view line = info.product_line;
  if (line.starts_with("OS-0-")) return 27.67;
  if (line.starts_with("OS-1-")) return 15.806;
  if (line.starts_with("OS-2-")) return 13.762;
  return kGenOneBeamOriginMm;
}
// Gen-1 OS-1 housing: lidar frame rotated 180 deg about z, 36.18 mm above the sensor origin.
constexpr std::array<double, 16> kDefaultLidarToSensorMm{-1, 0, 0, 0,     0, -1, 0, 0,
                                                         0,  0, 1, 36.18, 0, 0,  0, 1};
constexpr std::array<double, 16> kDefaultImuToSensorMm{1, 0, 0, 6.253, 0, 1, 0, -11.775,
                                                       0, 0, 1, 7.645, 0, 0, 0, 1};
constexpr int kDefaultImuMeasurementsPerPacket = 8;
constexpr long long kMaxColumns = 16384;
constexpr long long kMaxPixels = 512;

/// The sections a field can live in, for one of the two layouts.
struct Layout {
  JsonSection beams, data_format, config, info, lidar_intrinsics, imu_intrinsics, imu_format;
};

Layout locate(const Json& root, const JsonFields& fields) {
  const JsonSection top{&root, ""};
  Layout layout;
  if (top.find("beam_intrinsics") != nullptr || top.find("sensor_info") != nullptr) {
    auto section = [&](std::string_view key) {
      const Json* value = top.find(key);
      // Firmware 1.12/1.13 answered unknown commands with a string ("error: Command not
      // recognized."): such a section is absent, not malformed.
      if (value != nullptr && !value->is_object() && !value->is_string())
        fields.fail(key, "an object", value);
      return JsonSection{value != nullptr && value->is_object() ? value : nullptr,
                         std::string(key)};
    };
    layout.beams = section("beam_intrinsics");
    if (layout.beams.object == nullptr)
      fields.fail("beam_intrinsics", "an object with the beam angles", top.find("beam_intrinsics"));
    layout.data_format = section("lidar_data_format");
    layout.config = section("config_params");
    layout.info = section("sensor_info");
    layout.lidar_intrinsics = section("lidar_intrinsics");
    layout.imu_intrinsics = section("imu_intrinsics");
    layout.imu_format = section("imu_data_format");
    return layout;
  }
  if (top.find("beam_altitude_angles") == nullptr) {
    fields.failFile(
        "not Ouster sensor metadata: expected 'beam_intrinsics' (current layout) or "
        "'beam_altitude_angles' (legacy layout) at the top level");
  }
  const Json* data_format = top.find("data_format");
  if (data_format != nullptr && !data_format->is_object())
    fields.fail("data_format", "an object", data_format);
  layout.beams = layout.config = layout.info = layout.lidar_intrinsics = layout.imu_intrinsics =
      layout.imu_format = top;
  layout.imu_format.object = nullptr;
  layout.data_format = {data_format, "data_format"};
  return layout;
}

/// The first of `sections` that has `key`, with its name; {nullptr, name in the first}.
std::pair<const Json*, std::string> firstOf(std::initializer_list<const JsonSection*> sections,
                                            std::string_view key) {
  for (const JsonSection* section : sections) {
    if (const Json* value = section->find(key)) return {value, section->name(key)};
  }
  return {nullptr, (*sections.begin())->name(key)};
}

std::optional<FirmwareVersion> parseFirmwareVersion(const std::string& text) {
  static const std::regex kVersion(R"(v(\d+)\.(\d+)\.(\d+))");
  std::smatch match;
  if (!std::regex_search(text, match, kVersion)) return std::nullopt;
  std::array<int, 3> parts{};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string digits = match[i + 1].str();
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), parts[i]);
    if (ec != std::errc()) return std::nullopt;  // absurdly long numbers: no usable version
  }
  return FirmwareVersion{parts[0], parts[1], parts[2]};
}

/// "1024x10" -> {1024, 10}.
std::pair<int, int> parseLidarMode(const JsonFields& fields, const Json& value,
                                   const std::string& field) {
  const std::string expected = "a lidar mode such as \"1024x10\"";
  const std::string mode = fields.string(value, field, expected);
  int columns = 0, fps = 0;
  const char* first = mode.data();
  const char* last = mode.data() + mode.size();
  auto [x, ec] = std::from_chars(first, last, columns);
  if (ec != std::errc() || x == last || *x != 'x') fields.fail(field, expected, &value);
  auto [end, ec2] = std::from_chars(x + 1, last, fps);
  if (ec2 != std::errc() || end != last || columns <= 0 || fps <= 0 || columns > kMaxColumns)
    fields.fail(field, expected, &value);
  return {columns, fps};
}

template <class Enum, std::size_t N>
Enum parseProfile(const std::array<std::pair<Enum, std::string_view>, N>& table,
                  const std::string& name, Enum other) {
  for (const auto& [profile, spelling] : table)
    if (spelling == name) return profile;
  return other;
}

void parseFormat(const JsonFields& fields, const Layout& at, SensorInfo& info) {
  const auto [mode_value, mode_name] = firstOf({&at.config}, "lidar_mode");
  std::optional<std::pair<int, int>> mode;
  if (mode_value != nullptr) {
    mode = parseLidarMode(fields, *mode_value, mode_name);
    info.lidar_mode = mode_value->get<std::string>();
  }
  const JsonSection& df = at.data_format;
  if (const Json* v = df.find("columns_per_frame")) {
    info.columns_per_frame =
        static_cast<int>(fields.integer(*v, df.name("columns_per_frame"), 1, kMaxColumns));
    if (mode && mode->first != info.columns_per_frame) {
      fields.failFile(fmt::format("field '{}' = {} contradicts field '{}' = \"{}\"",
                                  df.name("columns_per_frame"), info.columns_per_frame, mode_name,
                                  info.lidar_mode));
    }
  } else if (mode) {
    info.columns_per_frame = mode->first;
  } else {
    fields.fail(mode_name, "a lidar mode such as \"1024x10\"", nullptr);
  }
  if (const Json* v = df.find("fps")) {
    info.frames_per_second = static_cast<int>(fields.integer(*v, df.name("fps"), 1, 1000));
  } else if (mode) {
    info.frames_per_second = mode->second;
  }
  if (info.lidar_mode.empty())
    info.lidar_mode = fmt::format("{}x{}", info.columns_per_frame, info.frames_per_second);

  const auto [cpp, cpp_name] = firstOf({&df, &at.config}, "columns_per_packet");
  if (cpp != nullptr) {
    info.columns_per_packet =
        static_cast<int>(fields.integer(*cpp, cpp_name, 1, info.columns_per_frame));
  } else {
    info.defaulted_fields.push_back(cpp_name);
  }

  const int beams = static_cast<int>(info.beam_altitude_angles_deg.size());
  if (const Json* v = df.find("pixels_per_column")) {
    info.pixels_per_column =
        static_cast<int>(fields.integer(*v, df.name("pixels_per_column"), 1, kMaxPixels));
    if (info.pixels_per_column != beams) {
      fields.failFile(fmt::format("field '{}' = {} does not match the {} beams of field '{}'",
                                  df.name("pixels_per_column"), info.pixels_per_column, beams,
                                  at.beams.name("beam_altitude_angles")));
    }
  } else {
    info.pixels_per_column = beams;
  }

  if (const Json* v = df.find("pixel_shift_by_row")) {
    const std::string field = df.name("pixel_shift_by_row");
    if (!v->is_array() || v->size() != static_cast<std::size_t>(beams))
      fields.fail(field, fmt::format("one integer per beam ({} values)", beams), v);
    for (std::size_t i = 0; i < v->size(); ++i) {
      info.pixel_shift_by_row.push_back(static_cast<int>(fields.integer(
          (*v)[i], fmt::format("{}[{}]", field, i), -info.columns_per_frame,
          info.columns_per_frame)));
    }
  }

  info.column_window = {0, info.columns_per_frame - 1};
  if (const Json* v = df.find("column_window")) {
    const std::string field = df.name("column_window");
    const std::string expected =
        fmt::format("two measurement ids [first, last] in [0, {}]", info.columns_per_frame - 1);
    if (!v->is_array() || v->size() != 2) fields.fail(field, expected, v);
    for (std::size_t i = 0; i < 2; ++i) {
      info.column_window[i] = static_cast<int>(
          fields.integer((*v)[i], fmt::format("{}[{}]", field, i), 0, info.columns_per_frame - 1));
    }
  }

  const auto [lp, lp_name] = firstOf({&df, &at.config}, "udp_profile_lidar");
  if (lp != nullptr) {
    info.lidar_profile_name = fields.string(*lp, lp_name, "a lidar UDP profile name");
    info.lidar_profile =
        parseProfile(kLidarProfiles, info.lidar_profile_name, LidarProfile::kOther);
  }
  const auto [ip, ip_name] = firstOf({&df, &at.config}, "udp_profile_imu");
  if (ip != nullptr) {
    info.imu_profile_name = fields.string(*ip, ip_name, "an IMU UDP profile name");
    info.imu_profile = parseProfile(kImuProfiles, info.imu_profile_name, ImuProfile::kOther);
  }
  const auto [ht, ht_name] = firstOf({&df, &at.config}, "header_type");
  if (ht != nullptr) info.header_type = fields.string(*ht, ht_name, "\"STANDARD\" or \"FUSA\"");

  if (info.imu_profile == ImuProfile::kAccel32Gyro32Nmea) {
    if (const Json* v = at.imu_format.find("imu_measurements_per_packet")) {
      info.imu_measurements_per_packet = static_cast<int>(
          fields.integer(*v, at.imu_format.name("imu_measurements_per_packet"), 1, 1000));
    } else {
      info.imu_measurements_per_packet = kDefaultImuMeasurementsPerPacket;
      info.defaulted_fields.push_back("imu_data_format.imu_measurements_per_packet");
    }
  }
}

void parseIdentity(const JsonFields& fields, const Layout& at, SensorInfo& info) {
  const JsonSection& s = at.info;
  if (const Json* v = s.find("prod_line"))
    info.product_line = fields.string(*v, s.name("prod_line"), "a product line string");
  if (const Json* v = s.find("prod_sn")) {
    const std::string field = s.name("prod_sn");
    if (v->is_string()) {
      const std::string text = v->get<std::string>();
      std::uint64_t serial = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), serial);
      if (ec != std::errc() || end != text.data() + text.size() || text.empty())
        fields.fail(field, "a serial number of digits", v);
      info.serial_number = serial;
    } else {
      info.serial_number =
          static_cast<std::uint64_t>(fields.integer(*v, field, 0, (1LL << 40) - 1));
    }
  }
  if (const Json* v = s.find("initialization_id")) {
    info.initialization_id = static_cast<std::uint32_t>(
        fields.integer(*v, s.name("initialization_id"), 0, (1 << 24) - 1));
  }
  const Json* image_rev = s.find("image_rev");
  const Json* build_rev = s.find("build_rev");
  if (image_rev != nullptr) info.firmware = fields.string(*image_rev, s.name("image_rev"), "text");
  std::string build;
  if (build_rev != nullptr) build = fields.string(*build_rev, s.name("build_rev"), "text");
  info.firmware_version = parseFirmwareVersion(info.firmware);
  if (!info.firmware_version) info.firmware_version = parseFirmwareVersion(build);
  if (info.firmware.empty()) info.firmware = build;

  for (auto [key, port] : {std::pair{"udp_port_lidar", &info.udp_port_lidar},
                           std::pair{"udp_port_imu", &info.udp_port_imu}}) {
    if (const Json* v = at.config.find(key))
      *port = static_cast<std::uint16_t>(fields.integer(*v, at.config.name(key), 0, 65535));
  }
}

void parseIntrinsics(const JsonFields& fields, const Layout& at, SensorInfo& info) {
  const JsonSection& b = at.beams;
  const std::string degrees = "an array of beam angles in degrees, one per beam";
  info.beam_altitude_angles_deg = fields.numbers(fields.require(b, "beam_altitude_angles", degrees),
                                                 b.name("beam_altitude_angles"), degrees);
  info.beam_azimuth_angles_deg = fields.numbers(
      fields.require(b, "beam_azimuth_angles", degrees), b.name("beam_azimuth_angles"),
      fmt::format("{} ({} values, as many as beam_altitude_angles)", degrees,
                  info.beam_altitude_angles_deg.size()),
      info.beam_altitude_angles_deg.size());
  if (info.beam_altitude_angles_deg.size() > static_cast<std::size_t>(kMaxPixels)) {
    fields.fail(b.name("beam_altitude_angles"), fmt::format("at most {} beam angles", kMaxPixels),
                b.find("beam_altitude_angles"));
  }
  for (std::size_t i = 0; i < info.beam_altitude_angles_deg.size(); ++i) {
    if (std::abs(info.beam_altitude_angles_deg[i]) > 90.0)
      fields.fail(fmt::format("{}[{}]", b.name("beam_altitude_angles"), i),
                  "an angle in [-90, 90] degrees", &(*b.find("beam_altitude_angles"))[i]);
    if (std::abs(info.beam_azimuth_angles_deg[i]) >= 360.0)
      fields.fail(fmt::format("{}[{}]", b.name("beam_azimuth_angles"), i),
                  "an angle in (-360, 360) degrees", &(*b.find("beam_azimuth_angles"))[i]);
  }

  if (const Json* v = b.find("lidar_origin_to_beam_origin_mm")) {
    const std::string field = b.name("lidar_origin_to_beam_origin_mm");
    info.lidar_origin_to_beam_origin_mm = fields.number(*v, field, "a distance in mm");
    if (info.lidar_origin_to_beam_origin_mm < 0.0 || info.lidar_origin_to_beam_origin_mm > 1000.0)
      fields.fail(field, "a distance in [0, 1000] mm", v);
  } else {
    info.lidar_origin_to_beam_origin_mm = defaultBeamOriginMm(info);
    info.defaulted_fields.push_back(b.name("lidar_origin_to_beam_origin_mm"));
  }
  if (const Json* v = b.find("beam_to_lidar_transform")) {
    info.T_lidar_beam = fields.transformMm(*v, b.name("beam_to_lidar_transform"));
  } else {
    info.T_lidar_beam =
        lie::SE3(lie::SO3(), Eigen::Vector3d(info.lidar_origin_to_beam_origin_mm * 1e-3, 0.0, 0.0));
  }

  const bool reduced = info.reduced_config;
  auto transform = [&](const JsonSection& section, const char* key,
                       const std::array<double, 16>& fallback) {
    if (const Json* v = section.find(key)) return fields.transformMm(*v, section.name(key));
    if (!reduced)
      fields.fail(section.name(key), "16 numbers (a 4x4 row-major transform, translation in mm)",
                  nullptr);
    info.defaulted_fields.push_back(section.name(key));
    return fields.transformMm(Json(fallback), section.name(key));
  };
  info.T_sensor_lidar =
      transform(at.lidar_intrinsics, "lidar_to_sensor_transform", kDefaultLidarToSensorMm);
  info.T_sensor_imu =
      transform(at.imu_intrinsics, "imu_to_sensor_transform", kDefaultImuToSensorMm);
}

SensorInfo parseRoot(const Json& root, const JsonFields& fields) {
  if (!root.is_object()) fields.failFile("expected a JSON object at the top level");
  const Layout at = locate(root, fields);
  SensorInfo info;
  info.source = fields.source();
  info.legacy_layout = at.beams.path.empty();
  // Ouster Studio's reduced config: beam angles and lidar_mode only.
  info.reduced_config = info.legacy_layout && at.info.find("prod_line") == nullptr &&
                        at.lidar_intrinsics.find("lidar_to_sensor_transform") == nullptr &&
                        at.data_format.object == nullptr;
  parseIdentity(fields, at, info);
  parseIntrinsics(fields, at, info);
  parseFormat(fields, at, info);
  if (info.reduced_config) {
    logger().warn(
        "{}: reduced sensor config (beam angles and lidar_mode only): assuming the LEGACY packet "
        "format with {} columns per packet and gen-1 OS-1 defaults for {}",
        info.source, info.columns_per_packet, fmt::join(info.defaulted_fields, ", "));
  }
  return info;
}

}  // namespace

int SensorInfo::windowColumns() const {
  const auto [first, last] = column_window;
  return first <= last ? last - first + 1 : columns_per_frame - first + last + 1;
}

bool SensorInfo::inWindow(int measurement_id) const {
  const auto [first, last] = column_window;
  if (measurement_id < 0 || measurement_id >= columns_per_frame) return false;
  return first <= last ? (measurement_id >= first && measurement_id <= last)
                       : (measurement_id >= first || measurement_id <= last);
}

std::string_view profileName(LidarProfile profile) {
  for (const auto& [p, name] : kLidarProfiles)
    if (p == profile) return name;
  return "unsupported";
}

std::string_view profileName(ImuProfile profile) {
  for (const auto& [p, name] : kImuProfiles)
    if (p == profile) return name;
  return "unsupported";
}

SensorInfo parseSensorInfo(std::string_view json_text, std::string_view source_name) {
  const JsonFields fields{std::string(source_name)};
  Json root;
  try {
    root = Json::parse(json_text);
  } catch (const Json::exception& e) {  // parse_error, or out_of_range for a number overflow
    fields.failFile(fmt::format("not valid JSON: {}", e.what()));
  }
  try {
    return parseRoot(root, fields);
  } catch (const Json::exception& e) {  // every access is type-checked first; kept as a net
    fields.failFile(fmt::format("unexpected JSON content: {}", e.what()));
  }
}

SensorInfo readSensorInfo(const std::filesystem::path& json_path) {
  const std::string name = json_path.string();
  if (std::filesystem::is_directory(json_path))
    throw InputError(fmt::format("{}: is a directory, expected a metadata JSON file", name));
  std::ifstream stream(json_path, std::ios::binary);
  if (!stream) throw InputError(fmt::format("{}: cannot open: {}", name, std::strerror(errno)));
  std::ostringstream text;
  text << stream.rdbuf();
  if (stream.bad()) throw InputError(fmt::format("{}: read error", name));
  return parseSensorInfo(text.str(), name);
}

}  // namespace taiga::io::ouster
