#include "taiga/eval/compare.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <nlohmann/json.hpp>

#include "json_helpers.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::eval {
namespace {

using nlohmann::json;

std::string runName(const std::filesystem::path& dir) {
  const std::filesystem::path normal = dir.lexically_normal();
  const std::string name =
      normal.has_filename() ? normal.filename().string() : normal.parent_path().filename().string();
  return name.empty() ? dir.string() : name;
}

// Columns of the table, formatted; "-" where a run has no value.
struct Row {
  std::vector<std::string> cells;
};

const std::vector<std::string>& headers() {
  static const std::vector<std::string> h{"run",
                                          "pairs",
                                          "APE RMSE (m)",
                                          "drift (m)",
                                          "drift (%)",
                                          "KITTI (%)",
                                          "KITTI (deg/100 m)",
                                          "mean time (ms)",
                                          "p95 time (ms)",
                                          "over period (%)",
                                          "RTF"};
  return h;
}

Row rowOf(const RunEvaluation& run) {
  const EvalResult& r = run.result;
  Row row;
  row.cells = {run.name,
               fmt::format("{}", r.pairs.size()),
               fmt::format("{:.6f}", r.ape.translation_m.rmse),
               fmt::format("{:.6f}", r.drift.drift_m),
               fmt::format("{:.4f}", r.drift.drift_percent),
               r.kitti ? fmt::format("{:.4f}", r.kitti->translation_error_percent) : "-",
               r.kitti ? fmt::format("{:.4f}", r.kitti->rotation_error_deg_per_100m) : "-"};
  if (run.timing) {
    const StageTiming& total = run.timing->total();
    row.cells.push_back(fmt::format("{:.3f}", total.mean_ms));
    row.cells.push_back(fmt::format("{:.3f}", total.p95_ms));
    row.cells.push_back(fmt::format("{:.2f}", run.timing->share_over_period * 100.0));
    row.cells.push_back(fmt::format("{:.3f}", run.timing->real_time_factor));
  } else {
    row.cells.insert(row.cells.end(), {"-", "-", "-", "-"});
  }
  return row;
}

}  // namespace

RunEvaluation evaluateRun(const std::filesystem::path& run_dir, const Trajectory& ref,
                          const std::string& ref_file, const EvalOptions& options,
                          double scan_period_s) {
  std::error_code error;
  if (!std::filesystem::is_directory(run_dir, error))
    throw InputError(fmt::format("{}: not a directory (expected an output directory of taiga run)",
                                 run_dir.string()));
  const std::filesystem::path trajectory_file = run_dir / "trajectory.tum";
  if (!std::filesystem::is_regular_file(trajectory_file, error))
    throw InputError(fmt::format(
        "{}: no trajectory.tum (expected an output directory of taiga run)", run_dir.string()));
  RunEvaluation run;
  run.run_dir = run_dir.string();
  run.name = runName(run_dir);
  const Trajectory est = io::readTum(trajectory_file);
  try {
    run.result = evaluate(est, ref, options);
  } catch (const InputError& e) {
    throw InputError(
        fmt::format("{} against {}: {}", trajectory_file.string(), ref_file, e.what()));
  }
  const std::filesystem::path timing_file = run_dir / "timing.csv";
  if (std::filesystem::is_regular_file(timing_file, error)) {
    run.timing_table = readTimingCsv(timing_file);
    run.timing = computeTimingStatistics(*run.timing_table, scan_period_s);
  }
  return run;
}

std::string formatCompareText(const CompareReport& report) {
  std::vector<Row> rows;
  for (const RunEvaluation& run : report.runs) rows.push_back(rowOf(run));
  std::vector<std::size_t> width;
  for (const std::string& h : headers()) width.push_back(h.size());
  for (const Row& row : rows)
    for (std::size_t c = 0; c < row.cells.size(); ++c)
      width[c] = std::max(width[c], row.cells[c].size());
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string out;
    for (std::size_t c = 0; c < cells.size(); ++c)
      out += c == 0 ? fmt::format("{:<{}}", cells[c], width[c])
                    : fmt::format("  {:>{}}", cells[c], width[c]);
    return out + "\n";
  };
  std::string out = fmt::format("reference {}; alignment {}; time per scan from timing.csv\n\n",
                                report.ref_file, alignmentName(report.options.alignment));
  out += line(headers());
  for (const Row& row : rows) out += line(row.cells);
  return out;
}

std::string formatCompareMarkdown(const CompareReport& report) {
  std::string out =
      fmt::format("Reference `{}`, alignment {}.\n\n| {} |\n|---|", report.ref_file,
                  alignmentName(report.options.alignment), fmt::join(headers(), " | "));
  for (std::size_t c = 1; c < headers().size(); ++c) out += "---:|";
  out += "\n";
  for (const RunEvaluation& run : report.runs)
    out += fmt::format("| {} |\n", fmt::join(rowOf(run).cells, " | "));
  return out;
}

std::string formatCompareJson(const CompareReport& report) {
  json runs = json::array();
  for (const RunEvaluation& run : report.runs) {
    const EvalResult& r = run.result;
    json j = {{"run", run.run_dir},
              {"name", run.name},
              {"poses", r.est_count},
              {"pairs", r.pairs.size()},
              {"ape_translation_m", detail::statisticsJson(r.ape.translation_m)},
              {"drift_m", r.drift.drift_m},
              {"drift_percent", r.drift.drift_percent},
              {"kitti_translation_error_percent",
               r.kitti ? json(r.kitti->translation_error_percent) : json(nullptr)},
              {"kitti_rotation_error_deg_per_100m",
               r.kitti ? json(r.kitti->rotation_error_deg_per_100m) : json(nullptr)}};
    j["timing"] = run.timing ? detail::timingJson(*run.timing, std::nullopt) : json(nullptr);
    runs.push_back(j);
  }
  return detail::dump({{"reference", report.ref_file},
                       {"alignment", std::string(alignmentName(report.options.alignment))},
                       {"runs", runs}});
}

std::string formatComparePlotData(const CompareReport& report, const Trajectory& ref) {
  json runs = json::array();
  for (const RunEvaluation& run : report.runs) {
    json j = {{"name", run.name},
              {"estimate", detail::seriesJson(run.result.est_aligned)},
              {"ape_m", run.result.ape.translation_error_m}};
    if (run.timing_table && run.timing)
      j["timing"] = detail::timingSeriesJson(*run.timing_table, *run.timing);
    runs.push_back(j);
  }
  return detail::dump({{"kind", "compare"},
                       {"ref_label", report.ref_file},
                       {"alignment", std::string(alignmentName(report.options.alignment))},
                       {"reference", detail::seriesJson(ref.poses())},
                       {"runs", runs}});
}

}  // namespace taiga::eval
