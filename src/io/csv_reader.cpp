#include "csv_reader.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "numeric_text.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io::detail {
namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string cell = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto first = cell.find_first_not_of(" \t\r");
    const auto last = cell.find_last_not_of(" \t\r");
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

bool skippable(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first == std::string::npos || line[first] == '#';
}

}  // namespace

CsvTable::CsvTable(const std::filesystem::path& path) : path_(path), stream_(path) {
  if (!stream_) throw InputError(fmt::format("{}: cannot open", path.string()));
  std::string line;
  while (std::getline(stream_, line)) {
    ++line_number_;
    if (skippable(line)) continue;
    names_ = splitCsv(line);
    return;
  }
  throw InputError(fmt::format("{}: empty; expected a header row naming the columns", path.string()));
}

std::optional<std::size_t> CsvTable::find(const std::string& column) const {
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == column) return i;
  }
  return std::nullopt;
}

std::size_t CsvTable::require(const std::string& column) const {
  if (auto i = find(column)) return *i;
  throw InputError(fmt::format("{}: no column '{}' in the header ({})", path_.string(), column, fmt::join(names_, ",")));
}

bool CsvTable::next(std::vector<double>& values) {
  std::string line;
  while (std::getline(stream_, line)) {
    ++line_number_;
    if (skippable(line)) continue;
    const std::vector<std::string> cells = splitCsv(line);
    if (cells.size() != names_.size()) fail(fmt::format("{} values, the header names {} columns", cells.size(), names_.size()));
    values.resize(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::optional<double> v = parseDouble(cells[i]);
      if (!v) fail(fmt::format("column '{}': '{}' is not a number", names_[i], cells[i]));
      values[i] = *v;
    }
    return true;
  }
  return false;
}

void CsvTable::fail(const std::string& message) const {
  throw InputError(fmt::format("{}:{}: {}", path_.string(), line_number_, message));
}

}  // namespace taiga::io::detail
