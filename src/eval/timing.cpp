#include "taiga/eval/timing.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

#include "taiga/core/errors.hpp"
#include "taiga/eval/statistics.hpp"

namespace taiga::eval {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> splitCommas(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

}  // namespace

TimingTable readTimingCsv(const std::filesystem::path& path) {
  std::ifstream stream(path);
  if (!stream) throw InputError(fmt::format("{}: cannot open the timing file", path.string()));
  const auto fail = [&](int line, const std::string& message) {
    throw InputError(fmt::format("{}:{}: {}", path.string(), line, message));
  };
  std::string line;
  int line_number = 0;
  std::vector<std::string> names;
  while (names.empty() && std::getline(stream, line)) {
    ++line_number;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    for (const std::string_view field : splitCommas(text)) names.emplace_back(field);
  }
  if (names.empty()) fail(line_number, "no header row (expected t_s,<stage>_ms,...,total_ms)");
  if (names.front() != "t_s")
    fail(line_number, fmt::format("the first column is '{}', expected t_s", names.front()));
  TimingTable table;
  table.columns.assign(names.begin() + 1, names.end());
  bool has_total = false;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    if (table.columns[c] == "total_ms") {
      table.total_column = c;
      has_total = true;
    }
  }
  if (!has_total)
    fail(line_number, fmt::format("no total_ms column in the header '{}'", trim(line)));
  table.values_ms.resize(table.columns.size());

  while (std::getline(stream, line)) {
    ++line_number;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const std::vector<std::string_view> fields = splitCommas(text);
    if (fields.size() != names.size())
      fail(line_number, fmt::format("expected {} values ({}), found {}", names.size(),
                                    fmt::join(names, ","), fields.size()));
    for (std::size_t c = 0; c < fields.size(); ++c) {
      double value = 0.0;
      const std::string_view f = fields[c];
      const auto [end, error] = std::from_chars(f.data(), f.data() + f.size(), value);
      if (error != std::errc() || end != f.data() + f.size() || !std::isfinite(value))
        fail(line_number, fmt::format("{}: '{}' is not a finite number", names[c], f));
      if (c == 0) {
        if (!table.t_s.empty() && !(value > table.t_s.back()))
          fail(line_number,
               fmt::format("t_s {} is not after the previous row's {}", value, table.t_s.back()));
        table.t_s.push_back(value);
      } else {
        if (value < 0.0) fail(line_number, fmt::format("{}: {} is negative", names[c], value));
        table.values_ms[c - 1].push_back(value);
      }
    }
  }
  if (table.t_s.empty()) fail(line_number, "no data rows after the header");
  return table;
}

const StageTiming& TimingStatistics::total() const { return stages[total_index]; }

TimingStatistics computeTimingStatistics(const TimingTable& table, double scan_period_s) {
  if (!(scan_period_s > 0.0) || !std::isfinite(scan_period_s))
    throw InputError(fmt::format("scan period {} s is not a positive number", scan_period_s));
  TimingStatistics s;
  s.scan_count = table.t_s.size();
  s.scan_period_s = scan_period_s;
  s.total_index = table.total_column;
  for (std::size_t c = 0; c < table.columns.size(); ++c) {
    const std::vector<double>& v = table.values_ms[c];
    const ErrorStatistics st = computeStatistics(v);
    s.stages.push_back({table.columns[c], st.mean, st.median, percentile(v, 95.0), st.max});
  }
  const std::vector<double>& total = table.values_ms[table.total_column];
  double sum_ms = 0.0;
  for (const double t : total) {
    sum_ms += t;
    if (t > scan_period_s * 1000.0) ++s.scans_over_period;
  }
  if (s.scan_count > 0) {
    s.share_over_period =
        static_cast<double>(s.scans_over_period) / static_cast<double>(s.scan_count);
    s.recording_duration_s = table.t_s.back() - table.t_s.front() + scan_period_s;
  }
  s.processing_s = sum_ms / 1000.0;
  if (s.processing_s > 0.0) s.real_time_factor = s.recording_duration_s / s.processing_s;
  return s;
}

}  // namespace taiga::eval
