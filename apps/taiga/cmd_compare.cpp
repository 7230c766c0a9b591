// taiga compare: one table and one plot over several runs (docs/evaluation.md).
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <vector>

#include "command.hpp"
#include "taiga/eval/compare.hpp"
#include "taiga/eval/plot.hpp"
#include "taiga/io/trajectory_io.hpp"

namespace taiga::app {
namespace {
struct CompareOptions {
  std::vector<std::string> runs;
  std::string reference;
  std::string align = "se3";
  double t_max_diff_s = 0.01;
  double t_offset_s = 0.0;
  double scan_period_s = 0.1;
  std::string plots;
  bool json = false;
  bool markdown = false;
};

int runCompare(const CompareOptions& options) {
  eval::CompareReport report;
  report.ref_file = options.reference;
  report.options.association = {options.t_max_diff_s, options.t_offset_s};
  report.options.alignment = eval::parseAlignment(options.align);
  const Trajectory ref = io::readTrajectory(options.reference);
  for (const std::string& run : options.runs)
    report.runs.push_back(
        eval::evaluateRun(run, ref, options.reference, report.options, options.scan_period_s));

  if (options.json)
    fmt::print("{}", eval::formatCompareJson(report));
  else if (options.markdown)
    fmt::print("{}", eval::formatCompareMarkdown(report));
  else
    fmt::print("{}", eval::formatCompareText(report));
  std::fflush(stdout);

  if (!options.plots.empty()) {
    const eval::PlotOutcome plots = eval::makePlots(eval::formatComparePlotData(report, ref),
                                                    options.plots, "compare_plot_data.json");
    if (!plots.ok) {
      fmt::print(stderr, "taiga compare: {}\n", plots.message);
      return kExitFailure;
    }
    for (const auto& file : plots.files) fmt::print(stderr, "wrote {}\n", file.string());
  }
  return kExitOk;
}
}  // namespace

Command addCompareCommand(CLI::App& tool) {
  auto options = std::make_shared<CompareOptions>();
  CLI::App* parser = tool.add_subcommand(
      "compare", "Tabulate and plot the accuracy of several runs against one reference");
  parser->add_option("RUN_DIR", options->runs, "Output directories of `taiga run`")->required();
  parser->add_option("--ref", options->reference, "Reference trajectory (TUM or KITTI)")
      ->required();
  parser
      ->add_option("--align", options->align,
                   "Alignment before comparing (evo: -a, -as, --align_origin)")
      ->check(CLI::IsMember({"se3", "sim3", "origin", "none"}))
      ->capture_default_str();
  parser
      ->add_option("--t-max-diff", options->t_max_diff_s,
                   "Largest time difference of associated poses, s (evo --t_max_diff)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  parser
      ->add_option("--t-offset", options->t_offset_s,
                   "Added to each estimate's times before associating, s (evo --t_offset)")
      ->capture_default_str();
  parser
      ->add_option("--scan-period-s", options->scan_period_s,
                   "Sensor period for the timing statistics, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option(
      "--plots", options->plots,
      "Write the overlay plots (compare_top.png, compare_ape.png) into this directory");
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  parser->add_flag("--markdown", options->markdown, "Print a Markdown table instead of text");
  return {parser, [options] { return runCompare(*options); }, options};
}

}  // namespace taiga::app
