#pragma once
// The evaluation as people and scripts read it: plain text, a Markdown table, JSON, and the
// series the plotting script draws.

#include <optional>
#include <string>

#include "taiga/eval/evaluate.hpp"
#include "taiga/eval/health_split.hpp"
#include "taiga/eval/map_sharpness.hpp"
#include "taiga/eval/timing.hpp"
#include "taiga/eval/tree_accuracy.hpp"

namespace taiga::eval {

struct EvalReport {
  std::string est_file, ref_file;
  EvalOptions options;
  EvalResult result;
  std::optional<std::string> timing_file;
  std::optional<TimingTable> timing_table;
  std::optional<TimingStatistics> timing;
  bool show_distance = false;  ///< include the distance distribution in text and Markdown
  /// `--map MAP --scene RECORDING`: the map's distance to the true surfaces (map_sharpness.hpp).
  std::optional<MapSharpness> map_sharpness;
  std::string map_file, scene_dir;
  /// `--scans RUN/scans.csv`: the APE by the health status of each pose's scan.
  std::optional<std::vector<StatusApe>> ape_by_status;
  /// The ok scans' poses evaluated alone (their own alignment), when some scans were not ok.
  std::optional<StatusApe> ok_self_aligned;
  std::string scans_file;
  /// `--trees TREES --ref-trees TREES`: the tree list against the reference one.
  std::optional<TreeAccuracy> trees;
  std::string trees_file, ref_trees_file;
};

/// Statistics with 6 decimals, as evo prints them.
std::string formatEvalText(const EvalReport& report);
std::string formatEvalMarkdown(const EvalReport& report);
/// One JSON object with every number at full precision (NaN and infinity as null).
std::string formatEvalJson(const EvalReport& report);
/// The series for scripts/plot_eval.py ("kind": "eval"): positions of the reference and the
/// aligned estimate, APE per pose over time and along the reference path, timing per scan.
std::string formatEvalPlotData(const EvalReport& report);

}  // namespace taiga::eval
