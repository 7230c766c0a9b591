#pragma once
// Several runs of `taiga run` against one reference: one row per run (like thesis Tables 3 and 4)
// and the series for one overlay plot.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "taiga/eval/evaluate.hpp"
#include "taiga/eval/timing.hpp"

namespace taiga::eval {

struct RunEvaluation {
  std::string run_dir;
  std::string name;  ///< the directory's name
  EvalResult result;
  std::optional<TimingTable> timing_table;  ///< from timing.csv when the run has one
  std::optional<TimingStatistics> timing;
};

/// Evaluates RUN_DIR/trajectory.tum against `ref`, with RUN_DIR/timing.csv when present.
/// InputError naming the directory or file on a missing or malformed file.
RunEvaluation evaluateRun(const std::filesystem::path& run_dir, const Trajectory& ref,
                          const std::string& ref_file, const EvalOptions& options,
                          double scan_period_s);

struct CompareReport {
  std::string ref_file;
  EvalOptions options;
  std::vector<RunEvaluation> runs;
};

std::string formatCompareText(const CompareReport& report);
std::string formatCompareMarkdown(const CompareReport& report);
std::string formatCompareJson(const CompareReport& report);
/// Series for scripts/plot_eval.py ("kind": "compare"): the reference and every aligned run.
std::string formatComparePlotData(const CompareReport& report, const Trajectory& ref);

}  // namespace taiga::eval
