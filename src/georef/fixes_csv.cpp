// The fixes CSV of `taiga georef --gnss FILE.csv` (format in georef_files.hpp and
// docs/georeferencing.md).
#include <fmt/format.h>

#include <array>
#include <charconv>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include "taiga/core/errors.hpp"
#include "taiga/georef/georef_files.hpp"

namespace taiga::georef {
namespace {

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string> splitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  for (std::string cell; std::getline(in, cell, ',');) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

double parseNumber(const std::string& cell, const std::string& where, const std::string& column) {
  double value = 0.0;
  const char* end = cell.data() + cell.size();
  const auto [ptr, error] = std::from_chars(cell.data(), end, value);
  if (cell.empty() || error != std::errc() || ptr != end || !std::isfinite(value))
    throw InputError(fmt::format("{}: column '{}': expected a finite number, got '{}'", where,
                                 column, cell));
  return value;
}

}  // namespace

std::vector<GnssFix> readFixesCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the GNSS fixes file", path.string()));
  constexpr std::array<const char*, 4> kRequired{"t_s", "latitude_deg", "longitude_deg", "height_m"};
  constexpr std::array<const char*, 3> kSigmas{"sigma_east_m", "sigma_north_m", "sigma_up_m"};
  std::map<std::string, std::size_t> column;
  std::size_t columns = 0;
  std::vector<GnssFix> fixes;
  std::size_t line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const std::string text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const std::vector<std::string> cells = splitCells(text);
    const std::string where = fmt::format("{}:{}", path.string(), line_number);
    if (column.empty()) {  // the header
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (!column.emplace(cells[i], i).second)
          throw InputError(fmt::format("{}: column '{}' appears twice in the header", where, cells[i]));
      }
      for (const char* name : kRequired)
        if (!column.contains(name))
          throw InputError(fmt::format(
              "{}: the header has no column '{}' (required: t_s, latitude_deg, longitude_deg, "
              "height_m; optional: sigma_east_m, sigma_north_m, sigma_up_m, status)",
              where, name));
      const int sigmas = static_cast<int>(column.contains(kSigmas[0])) +
                         static_cast<int>(column.contains(kSigmas[1])) +
                         static_cast<int>(column.contains(kSigmas[2]));
      if (sigmas != 0 && sigmas != 3)
        throw InputError(fmt::format(
            "{}: give all three of sigma_east_m, sigma_north_m, sigma_up_m or none", where));
      columns = cells.size();
      continue;
    }
    if (cells.size() != columns)
      throw InputError(fmt::format("{}: {} values, the header has {} columns", where, cells.size(),
                                   columns));
    const auto value = [&](const char* name) { return parseNumber(cells[column.at(name)], where, name); };
    GnssFix fix;
    fix.t_s = value("t_s");
    fix.latitude_deg = value("latitude_deg");
    fix.longitude_deg = value("longitude_deg");
    fix.height_ellipsoid_m = value("height_m");
    if (std::abs(fix.latitude_deg) > 90.0)
      throw InputError(fmt::format("{}: column 'latitude_deg': {} is outside [-90, 90]", where, fix.latitude_deg));
    if (std::abs(fix.longitude_deg) > 180.0)
      throw InputError(fmt::format("{}: column 'longitude_deg': {} is outside [-180, 180]", where, fix.longitude_deg));
    if (column.contains(kSigmas[0])) {
      Eigen::Vector3d sigma;
      for (int k = 0; k < 3; ++k) {
        sigma[k] = value(kSigmas[k]);
        if (!(sigma[k] > 0.0))
          throw InputError(fmt::format("{}: column '{}': a sigma must be positive, got {}", where,
                                       kSigmas[k], sigma[k]));
      }
      fix.covariance_enu_m2 = sigma.cwiseProduct(sigma).asDiagonal();
      fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
    }
    fix.status = GnssStatus::kFix;
    if (column.contains("status")) {
      const double status = value("status");
      if (status != -1.0 && status != 0.0 && status != 1.0 && status != 2.0)
        throw InputError(fmt::format(
            "{}: column 'status': expected -1 (no fix), 0 (fix), 1 (SBAS) or 2 (GBAS), got {}",
            where, status));
      fix.status = static_cast<GnssStatus>(static_cast<int>(status));
    }
    if (!fixes.empty() && !(fix.t_s > fixes.back().t_s))
      throw InputError(fmt::format("{}: column 't_s': {} is not after the previous fix's {}",
                                   where, fix.t_s, fixes.back().t_s));
    fixes.push_back(fix);
  }
  if (column.empty())
    throw InputError(fmt::format("{}: empty file, expected a header line and fixes", path.string()));
  return fixes;
}

}  // namespace taiga::georef
