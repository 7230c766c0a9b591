#include "taiga/eval/health_split.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include "taiga/core/errors.hpp"

namespace taiga::eval {
namespace {

/// The fields of one CSV line; a field in double quotes may hold commas ("" is a quote).
std::vector<std::string> csvFields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      fields.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

std::size_t columnOf(const std::vector<std::string>& header, const std::string& name,
                     const std::filesystem::path& path) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end())
    throw InputError(
        fmt::format("{}:1: no column '{}' (a scans.csv of taiga run, which writes it "
                    "since the health monitor)",
                    path.string(), name));
  return static_cast<std::size_t>(it - header.begin());
}

}  // namespace

std::vector<ScanStatusAt> readScanStatuses(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the scans file", path.string()));
  std::string line;
  if (!std::getline(in, line)) throw InputError(fmt::format("{}: empty", path.string()));
  const std::vector<std::string> header = csvFields(line);
  const std::size_t t_column = columnOf(header, "t_s", path);
  const std::size_t status_column = columnOf(header, "status", path);
  std::vector<ScanStatusAt> scans;
  for (int line_number = 2; std::getline(in, line); ++line_number) {
    if (line.empty()) continue;
    const std::vector<std::string> fields = csvFields(line);
    const auto fail = [&](const std::string& problem) {
      throw InputError(fmt::format("{}:{}: {}", path.string(), line_number, problem));
    };
    if (fields.size() != header.size())
      fail(fmt::format("{} fields, the header has {}", fields.size(), header.size()));
    ScanStatusAt scan;
    try {
      std::size_t used = 0;
      scan.t_s = std::stod(fields[t_column], &used);
      if (used != fields[t_column].size()) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      fail(fmt::format("column 't_s': expected a number, got '{}'", fields[t_column]));
    }
    if (!std::isfinite(scan.t_s)) fail("column 't_s': not finite");
    if (!scans.empty() && scan.t_s < scans.back().t_s) fail("column 't_s': goes back in time");
    scan.status = fields[status_column];
    scans.push_back(std::move(scan));
  }
  return scans;
}

namespace {

/// The first scan ending at or after t_s (a microsecond of slack for printed stamps), if any.
const ScanStatusAt* scanOf(double t_s, const std::vector<ScanStatusAt>& scans) {
  const auto scan = std::lower_bound(scans.begin(), scans.end(), t_s - 1e-6,
                                     [](const ScanStatusAt& s, double t) { return s.t_s < t; });
  return scan == scans.end() ? nullptr : &*scan;
}

}  // namespace

Trajectory posesWithStatus(const Trajectory& estimate, const std::vector<ScanStatusAt>& scans,
                           const std::string& status) {
  Trajectory out;
  for (const StampedPose& p : estimate.poses()) {
    const ScanStatusAt* scan = scanOf(p.t_s, scans);
    if (scan && scan->status == status) out.append(p.t_s, p.pose);
  }
  return out;
}

std::vector<StatusApe> apeByStatus(const EvalResult& result,
                                   const std::vector<ScanStatusAt>& scans) {
  const std::vector<std::string> order = {"ok", "degraded", "lost"};
  std::vector<std::vector<double>> errors(order.size());
  const std::vector<double>& e = result.ape.translation_error_m;
  for (std::size_t i = 0; i < e.size() && i < result.pairs.est.size(); ++i) {
    const ScanStatusAt* scan = scanOf(result.pairs.est[i].t_s, scans);
    if (!scan) continue;
    const auto k = std::find(order.begin(), order.end(), scan->status);
    if (k != order.end()) errors[static_cast<std::size_t>(k - order.begin())].push_back(e[i]);
  }
  std::vector<StatusApe> out;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (errors[k].empty()) continue;
    double sum_sq = 0.0;
    for (double x : errors[k]) sum_sq += x * x;
    out.push_back({order[k], errors[k].size(),
                   std::sqrt(sum_sq / static_cast<double>(errors[k].size())),
                   *std::max_element(errors[k].begin(), errors[k].end())});
  }
  return out;
}

}  // namespace taiga::eval
