#include "taiga/trees/tree_files.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "taiga/core/errors.hpp"

namespace taiga::trees {
namespace {

Eigen::Vector3d groundPoint(const Stem& s) {
  return Eigen::Vector3d(s.position_m.x() - s.axis_slope.x() * (s.position_m.z() - s.ground_z_m),
                         s.position_m.y() - s.axis_slope.y() * (s.position_m.z() - s.ground_z_m),
                         s.ground_z_m);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (!fields.empty() && !fields.back().empty() && fields.back().back() == '\r')
    fields.back().pop_back();
  return fields;
}

}  // namespace

void writeTreesCsv(const std::filesystem::path& path, std::span<const Stem> stems,
                   const Eigen::Vector3d& offset_m, const std::optional<GridFrame>& grid) {
  auto out = fmt::output_file(path.string());
  out.print(
      "id,x_m,y_m,z_m,x_bh_m,y_bh_m,dbh_m,dbh_sigma_m,height_m,lean_deg,lean_azimuth_deg,points,"
      "fit_rms_m,arc_deg,slices,quality{}\n",
      grid ? ",easting_m,northing_m,ground_height_m" : "");
  for (std::size_t i = 0; i < stems.size(); ++i) {
    const Stem& s = stems[i];
    const Eigen::Vector3d base = groundPoint(s) + offset_m;
    const Eigen::Vector3d bh = s.position_m + offset_m;
    out.print(
        "{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.2f},{:.2f},{:.1f},{},{:.4f},{:.0f},"
        "{},{}",
        i + 1, base.x(), base.y(), base.z(), bh.x(), bh.y(), s.dbh_m, s.dbh_sigma_m, s.height_m,
        s.lean_deg, s.lean_azimuth_deg, s.points, s.fit_rms_m, s.arc_deg, s.slices,
        qualityName(s.quality));
    if (grid) {
      const Eigen::Vector3d bh_grid = grid->T_epsg_local * s.position_m;
      const Eigen::Vector3d ground_grid =
          grid->T_epsg_local * Eigen::Vector3d(s.position_m.x(), s.position_m.y(), s.ground_z_m);
      out.print(",{:.3f},{:.3f},{:.3f}", bh_grid.x(), bh_grid.y(), ground_grid.z());
    }
    out.print("\n");
  }
}

void writeTreesGeoJson(const std::filesystem::path& path, std::span<const Stem> stems,
                       const Eigen::Vector3d& offset_m, const std::optional<GridFrame>& grid) {
  nlohmann::ordered_json features = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < stems.size(); ++i) {
    const Stem& s = stems[i];
    const Eigen::Vector3d p = grid ? Eigen::Vector3d(grid->T_epsg_local * s.position_m)
                                   : Eigen::Vector3d(s.position_m + offset_m);
    nlohmann::ordered_json feature;
    feature["type"] = "Feature";
    feature["properties"] = {{"id", i + 1},
                             {"dbh_m", std::round(s.dbh_m * 1e4) / 1e4},
                             {"dbh_cm", std::round(s.dbh_m * 1e3) / 10},
                             {"height_m", std::round(s.height_m * 100) / 100},
                             {"quality", qualityName(s.quality)}};
    feature["geometry"] = {
        {"type", "Point"},
        {"coordinates", {std::round(p.x() * 1e3) / 1e3, std::round(p.y() * 1e3) / 1e3}}};
    features.push_back(std::move(feature));
  }
  nlohmann::ordered_json geojson;
  geojson["type"] = "FeatureCollection";
  geojson["name"] = "trees";
  if (grid)
    geojson["crs"] = {
        {"type", "name"},
        {"properties", {{"name", fmt::format("urn:ogc:def:crs:EPSG::{}", grid->epsg)}}}};
  geojson["features"] = std::move(features);
  fmt::output_file(path.string()).print("{}\n", geojson.dump(1));
}

std::vector<TreeRecord> readTreesCsv(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the tree list", path.string()));
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  return parseTreesCsv(text, path.string());
}

std::vector<TreeRecord> parseTreesCsv(const std::string& text, const std::string& source) {
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line))
    throw InputError(fmt::format("{}: empty file, expected a header row", source));
  std::map<std::string, std::size_t> column;
  const std::vector<std::string> names = splitCsv(line);
  for (std::size_t i = 0; i < names.size(); ++i) column[names[i]] = i;
  auto find = [&](const char* name) -> std::optional<std::size_t> {
    const auto it = column.find(name);
    return it == column.end() ? std::nullopt : std::optional(it->second);
  };
  auto require = [&](const char* name) {
    const auto c = find(name);
    if (!c)
      throw InputError(fmt::format("{}: no column '{}' in the header '{}'", source, name, line));
    return *c;
  };
  const std::size_t c_id = require("id"), c_dbh = require("dbh_m");
  const bool has_bh = find("x_bh_m") && find("y_bh_m");
  const std::size_t c_x = has_bh ? *find("x_bh_m") : require("x_m");
  const std::size_t c_y = has_bh ? *find("y_bh_m") : require("y_m");
  const auto c_z = find("z_m"), c_height = find("height_m"), c_sigma = find("dbh_sigma_m");
  const auto c_lean = find("lean_deg"), c_lean_azimuth = find("lean_azimuth_deg");

  std::vector<TreeRecord> trees;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> fields = splitCsv(line);
    if (fields.size() != names.size())
      throw InputError(fmt::format("{}:{}: {} values, the header names {}", source, number,
                                   fields.size(), names.size()));
    auto number_in = [&](std::size_t c) {
      double value = 0.0;
      const std::string& field = fields[c];
      const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
      if (error != std::errc() || end != field.data() + field.size() || !std::isfinite(value))
        throw InputError(fmt::format("{}:{}: column '{}': '{}' is not a finite number", source,
                                     number, names[c], field));
      return value;
    };
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    TreeRecord t;
    const double id = number_in(c_id);
    if (std::abs(id) > 1e15 || id != std::round(id))
      throw InputError(
          fmt::format("{}:{}: column 'id': {} is not an integer id", source, number, id));
    t.id = static_cast<long>(id);
    t.bh_xy_m = Eigen::Vector2d(number_in(c_x), number_in(c_y));
    t.ground_z_m = c_z ? number_in(*c_z) : kNaN;
    t.dbh_m = number_in(c_dbh);
    t.dbh_sigma_m = c_sigma ? number_in(*c_sigma) : kNaN;
    t.height_m = c_height ? number_in(*c_height) : kNaN;
    t.lean_deg = c_lean ? number_in(*c_lean) : kNaN;
    t.lean_azimuth_deg = c_lean_azimuth ? number_in(*c_lean_azimuth) : kNaN;
    trees.push_back(t);
  }
  return trees;
}

}  // namespace taiga::trees
