#pragma once
// Processing time per scan, from the timing.csv that `taiga run` writes (docs/evaluation.md):
// a header row, then one row per scan, comma separated:
//
//   t_s,<stage>_ms,...,total_ms
//
// t_s is the scan's time on the recording's clock (s), each stage column its duration in
// milliseconds, total_ms the whole per-scan processing time. The first column must be t_s and a
// total_ms column must exist; the stage columns between them are whatever the pipeline measures.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace taiga::eval {

struct TimingTable {
  std::vector<std::string> columns;            ///< the duration columns, total_ms included
  std::vector<double> t_s;                     ///< one per scan
  std::vector<std::vector<double>> values_ms;  ///< values_ms[column][scan]
  std::size_t total_column = 0;                ///< index of total_ms in `columns`
};

/// Reads timing.csv; InputError("FILE:LINE: ...") naming the column on malformed input
/// (missing t_s or total_ms, a value that is not a finite number, a negative duration, a wrong
/// number of values, no rows).
TimingTable readTimingCsv(const std::filesystem::path& path);

struct StageTiming {
  std::string name;  ///< column name, e.g. "register_ms"
  double mean_ms = 0.0, median_ms = 0.0, p95_ms = 0.0, max_ms = 0.0;
};

/// Timing statistics. p95 is numpy.percentile(values, 95) (linear interpolation).
///   scans_over_period: scans whose total_ms > scan_period_s x 1000
///   recording_duration_s = t_last - t_first + scan_period_s (n scans cover n periods)
///   processing_s = sum of total_ms / 1000
///   real_time_factor = recording_duration_s / processing_s: how many times faster than the
///     sensor the processing ran (>= 1 keeps up on average).
struct TimingStatistics {
  std::size_t scan_count = 0;
  std::vector<StageTiming> stages;  ///< in the file's column order, total_ms included
  double scan_period_s = 0.1;
  std::size_t scans_over_period = 0;
  double share_over_period = 0.0;  ///< scans_over_period / scan_count, in [0, 1]
  double recording_duration_s = 0.0;
  double processing_s = 0.0;
  double real_time_factor = 0.0;     ///< 0 when processing_s is 0
  const StageTiming& total() const;  ///< the total_ms entry
  std::size_t total_index = 0;
};

/// InputError when scan_period_s is not positive.
TimingStatistics computeTimingStatistics(const TimingTable& table, double scan_period_s = 0.1);

}  // namespace taiga::eval
