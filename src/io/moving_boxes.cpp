#include "taiga/io/moving_boxes.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <string>

#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

constexpr std::array<std::string_view, 12> kColumns = {
    "scan_stamp_s", "box_id", "cx", "cy", "cz", "hx", "hy", "hz", "qw", "qx", "qy", "qz"};
// Quaternions written with a few digits; further from unit length is not a rotation.
constexpr double kQuaternionNormTolerance = 1e-2;

std::vector<std::string_view> splitCommas(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string_view cell = line.substr(start, comma - start);
    while (!cell.empty() && (cell.front() == ' ' || cell.front() == '\t')) cell.remove_prefix(1);
    while (!cell.empty() && (cell.back() == ' ' || cell.back() == '\t' || cell.back() == '\r'))
      cell.remove_suffix(1);
    out.push_back(cell);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

MovingBoxes readMovingBoxes(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the moving-boxes file", path.string()));
  const std::string expected_header = fmt::format("{}", fmt::join(kColumns, ","));
  MovingBoxes boxes;
  std::string line;
  int line_number = 0;
  bool header_seen = false;
  auto fail = [&](const std::string& problem) {
    throw InputError(fmt::format("{}:{}: {}", path.string(), line_number, problem));
  };
  while (std::getline(in, line)) {
    ++line_number;
    const auto cells = splitCommas(line);
    if (cells.size() == 1 && cells[0].empty()) continue;
    if (!cells[0].empty() && cells[0].front() == '#') continue;
    if (!header_seen) {
      if (cells.size() != kColumns.size() ||
          !std::equal(cells.begin(), cells.end(), kColumns.begin())) {
        fail(fmt::format("expected the header '{}'", expected_header));
      }
      header_seen = true;
      continue;
    }
    if (cells.size() != kColumns.size()) {
      fail(fmt::format("expected {} values ({}), found {}", kColumns.size(), expected_header,
                       cells.size()));
    }
    std::array<double, kColumns.size()> v{};
    for (std::size_t c = 0; c < kColumns.size(); ++c) {
      const auto value = detail::parseDouble(cells[c]);
      if (!value || !std::isfinite(*value)) {
        fail(fmt::format("{}: '{}' is not a finite number", kColumns[c], cells[c]));
      }
      v[c] = *value;
    }
    OrientedBox box;
    box.center_m = {v[2], v[3], v[4]};
    box.half_extent_m = {v[5], v[6], v[7]};
    if (!(box.half_extent_m.array() >= 0.0).all()) {
      fail("hx, hy, hz: half extents must not be negative");
    }
    const Eigen::Quaterniond q(v[8], v[9], v[10], v[11]);
    if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
      fail(fmt::format("qw, qx, qy, qz = ({}, {}, {}, {}) has norm {:.4f}; expected a unit "
                       "quaternion, w first",
                       v[8], v[9], v[10], v[11], q.norm()));
    }
    box.R_frame_box = q.normalized().toRotationMatrix();
    boxes.add(v[0], box);
  }
  if (!header_seen) {
    throw InputError(fmt::format("{}: empty; expected the header '{}' and one row per box",
                                 path.string(), expected_header));
  }
  return boxes;
}

}  // namespace taiga::io
