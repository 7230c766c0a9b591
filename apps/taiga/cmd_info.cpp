// taiga info: what a recording contains, and whether its timestamps look right.
#include <fmt/format.h>

#include <memory>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/io/recording_summary.hpp"

namespace taiga::app {
namespace {
struct InfoOptions {
  std::string recording;
  std::string config;
  bool json = false;
};

int runInfo(const InfoOptions& options) {
  const SystemConfig config = loadConfig(options.config);
  const auto announced = io::announcedScanCount(options.recording, config.recording);
  Progress progress("reading", announced.value_or(0), "scans", stderr, announced.has_value() && isatty(fileno(stderr)));
  const io::RecordingSummary summary =
      io::summarizeRecording(options.recording, config.recording, config.rig, [&](std::size_t n) { progress.update(n); });
  progress.finish();
  fmt::print("{}", options.json ? io::formatSummaryJson(summary) : io::formatSummaryText(summary));
  return summary.error ? kExitBadInput : kExitOk;
}
}  // namespace

Command addInfoCommand(CLI::App& tool) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* parser = tool.add_subcommand(
      "info", "Show the streams, rates, point fields, per-point time checks and duration of a recording");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")->required();
  addConfigOption(*parser, options->config);
  parser->add_flag("--json", options->json, "Print one JSON object instead of text");
  return {parser, [options] { return runInfo(*options); }, options};
}

}  // namespace taiga::app
