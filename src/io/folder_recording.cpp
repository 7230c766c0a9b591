#include "taiga/io/folder_recording.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "csv_reader.hpp"
#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/imu_units.hpp"

namespace taiga::io {
namespace {

// A file name's time: seconds with a fraction, or whole nanoseconds (more than 15 digits), split
// into seconds and nanoseconds as ROS does so that both spellings give the same double.
std::optional<double> stampFromName(const std::filesystem::path& file) {
  const std::string stem = file.stem().string();
  const std::optional<double> value = detail::parseDouble(stem);
  if (!value || !std::isfinite(*value) || *value < 0.0) return std::nullopt;
  const bool whole_nanoseconds = stem.size() > 15 && std::all_of(stem.begin(), stem.end(), ::isdigit);
  if (!whole_nanoseconds) return *value;
  return *detail::parseDouble(stem.substr(0, stem.size() - 9)) + 1e-9 * *detail::parseDouble(stem.substr(stem.size() - 9));
}

class FolderScanStream final : public StreamSource {
 public:
  FolderScanStream(std::vector<FolderScanFile> files, const RecordingConfig& config)
      : files_(std::move(files)), options_{config.scan_period_s, config.point_time_field, config.pointsAtStamp()} {}

  std::string name() const override { return "scans/"; }
  std::vector<std::string> details() const override { return details_; }

  std::optional<RecordingEvent> next() override {
    while (next_ < files_.size()) {
      const FolderScanFile& file = files_[next_++];
      DecodedPoints decoded = readPointCloudFile(file.path, file.stamp_s, options_);
      if (!reported_times_) {
        reported_times_ = true;
        details_ = {fmt::format("{} scan files", files_.size()), fmt::format("per-point times: {}", decoded.time_description)};
        const bool guessed = timesInvented(decoded.time_source);
        logger().log(guessed ? spdlog::level::warn : spdlog::level::info, "{}: per-point times: {}{}",
                     file.path.parent_path().string(), decoded.time_description,
                     guessed ? " (clouds deskewed upstream: recording.deskewed: true)" : "");
      }
      if (decoded.cloud.empty()) {
        logger().warn("{}: no valid point; skipped", file.path.string());
        continue;
      }
      Scan scan;
      scan.index = scan_count_++;
      std::tie(scan.t_start_s, scan.t_end_s) = decoded.cloud.timeSpan();
      scan.cloud_in_lidar = std::move(decoded.cloud);
      scan.times_invented = timesInvented(decoded.time_source);
      return scan;
    }
    return std::nullopt;
  }

 private:
  std::vector<FolderScanFile> files_;
  PointDecodeOptions options_;
  std::size_t next_ = 0;
  std::uint64_t scan_count_ = 0;
  bool reported_times_ = false;
  std::vector<std::string> details_;
};

class ImuCsvStream final : public StreamSource {
 public:
  explicit ImuCsvStream(const std::filesystem::path& path) : table_(path) {
    for (const char* column : {"t_s", "ax", "ay", "az", "wx", "wy", "wz"}) columns_.push_back(table_.require(column));
    for (const char* column : {"qx", "qy", "qz", "qw"}) {
      if (auto i = table_.find(column)) orientation_columns_.push_back(*i);
    }
    if (!orientation_columns_.empty() && orientation_columns_.size() != 4) {
      throw InputError(fmt::format("{}: give all of qx, qy, qz, qw or none", path.string()));
    }
  }

  std::string name() const override { return "imu.csv"; }

  std::optional<RecordingEvent> next() override {
    if (!table_.next(values_)) return std::nullopt;
    auto v = [&](std::size_t k) { return values_[columns_[k]]; };
    ImuSample sample;
    sample.t_s = v(0);
    sample.acceleration_imu_mps2 = {v(1), v(2), v(3)};
    sample.angular_velocity_imu_radps = {v(4), v(5), v(6)};
    if (!orientation_columns_.empty()) {
      const auto& q = orientation_columns_;
      const Eigen::Quaterniond orientation(values_[q[3]], values_[q[0]], values_[q[1]], values_[q[2]]);
      if (std::abs(orientation.norm() - 1.0) > 1e-2) table_.fail("qx, qy, qz, qw is not a unit quaternion");
      sample.orientation = ImuOrientation{orientation.normalized(), OrientationReference::kEnu};
    }
    if (!std::isfinite(sample.t_s) || !sample.acceleration_imu_mps2.allFinite() || !sample.angular_velocity_imu_radps.allFinite()) {
      table_.fail("non-finite value");
    }
    return sample;
  }

 private:
  detail::CsvTable table_;
  std::vector<std::size_t> columns_, orientation_columns_;
  std::vector<double> values_;
};

class GnssCsvStream final : public StreamSource {
 public:
  explicit GnssCsvStream(const std::filesystem::path& path) : table_(path) {
    for (const char* column : {"t_s", "lat_deg", "lon_deg", "height_m"}) columns_.push_back(table_.require(column));
    for (const char* column : {"var_e_m2", "var_n_m2", "var_u_m2"}) {
      if (auto i = table_.find(column)) variance_columns_.push_back(*i);
    }
    if (!variance_columns_.empty() && variance_columns_.size() != 3) {
      throw InputError(fmt::format("{}: give all of var_e_m2, var_n_m2, var_u_m2 or none", path.string()));
    }
    status_column_ = table_.find("status");
  }

  std::string name() const override { return "gnss.csv"; }

  std::optional<RecordingEvent> next() override {
    if (!table_.next(values_)) return std::nullopt;
    GnssFix fix;
    fix.t_s = values_[columns_[0]];
    fix.latitude_deg = values_[columns_[1]];
    fix.longitude_deg = values_[columns_[2]];
    fix.height_ellipsoid_m = values_[columns_[3]];
    if (!(std::abs(fix.latitude_deg) <= 90.0 && std::abs(fix.longitude_deg) <= 180.0 && std::isfinite(fix.height_ellipsoid_m))) {
      table_.fail(fmt::format("latitude {} / longitude {} / height {} is not a position", fix.latitude_deg, fix.longitude_deg,
                              fix.height_ellipsoid_m));
    }
    if (!variance_columns_.empty()) {
      fix.covariance_enu_m2 = Eigen::Vector3d(values_[variance_columns_[0]], values_[variance_columns_[1]], values_[variance_columns_[2]]).asDiagonal();
      fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
    }
    fix.status = GnssStatus::kFix;
    if (status_column_) {
      const double status = values_[*status_column_];
      if (!(status >= -1 && status <= 2 && status == std::trunc(status))) table_.fail("status must be -1, 0, 1 or 2");
      fix.status = static_cast<GnssStatus>(static_cast<int>(status));
    }
    return fix;
  }

 private:
  detail::CsvTable table_;
  std::vector<std::size_t> columns_, variance_columns_;
  std::optional<std::size_t> status_column_;
  std::vector<double> values_;
};

}  // namespace

bool isFolderRecording(const std::filesystem::path& dir) {
  return std::filesystem::is_directory(dir) &&
         (std::filesystem::is_directory(dir / "scans") || std::filesystem::is_regular_file(dir / "imu.csv"));
}

std::vector<FolderScanFile> listFolderScans(const std::filesystem::path& dir) {
  const std::filesystem::path scans = dir / "scans";
  if (!std::filesystem::is_directory(scans)) {
    throw InputError(fmt::format("{}: no scans/ directory (see docs/recordings.md for the folder layout)", dir.string()));
  }
  std::vector<FolderScanFile> files;
  for (const auto& entry : std::filesystem::directory_iterator(scans)) {
    const std::string extension = lowercaseExtension(entry.path());
    if (!entry.is_regular_file() || (extension != ".pcd" && extension != ".ply")) continue;
    const std::optional<double> stamp = stampFromName(entry.path());
    if (!stamp) {
      throw InputError(fmt::format("{}: the file name must be the scan's start time, in s (1700000000.1.pcd) or ns "
                                   "(1700000000100000000.pcd)",
                                   entry.path().string()));
    }
    files.push_back({entry.path(), *stamp});
  }
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) { return a.stamp_s < b.stamp_s; });
  for (std::size_t i = 1; i < files.size(); ++i) {
    if (files[i].stamp_s - files[i - 1].stamp_s < 1e-6) {
      throw InputError(fmt::format("{} and {} have the same time", files[i - 1].path.string(), files[i].path.string()));
    }
  }
  if (files.empty()) throw InputError(fmt::format("{}: no .pcd or .ply files", scans.string()));
  return files;
}

std::vector<std::unique_ptr<StreamSource>> openFolderStreams(const std::filesystem::path& dir, const RecordingConfig& recording,
                                                             const RigConfig& rig) {
  std::vector<std::unique_ptr<StreamSource>> streams;
  streams.push_back(std::make_unique<FolderScanStream>(listFolderScans(dir), recording));
  if (std::filesystem::exists(dir / "imu.csv")) {
    streams.push_back(withAccelerationUnit(std::make_unique<ImuCsvStream>(dir / "imu.csv"), rig.imu_acceleration_unit, dir.string()));
  } else {
    logger().warn("{}: no imu.csv", dir.string());
  }
  if (std::filesystem::exists(dir / "gnss.csv")) streams.push_back(std::make_unique<GnssCsvStream>(dir / "gnss.csv"));
  return streams;
}

}  // namespace taiga::io
