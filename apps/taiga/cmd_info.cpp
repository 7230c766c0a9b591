// taiga info: what a recording contains, and whether its timestamps look right.
#include <fmt/format.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/io/recording_summary.hpp"
#include "taiga/pipeline/sweep_check.hpp"

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
  // recording.deskewed: auto judges clouds without per-point times by their seams, as taiga run
  // will (pipeline/sweep_check.hpp).
  std::optional<pipeline::SweepCheck> sweep;
  if (!summary.error && summary.scans.scans_with_invented_times > 0 &&
      config.recording.deskewed == RecordingConfig::Deskewed::kAuto)
    sweep = pipeline::checkSweeps(options.recording, config);
  if (options.json) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(io::formatSummaryJson(summary));
    if (sweep)
      j["sweep_check"] = {{"verdict", pipeline::toString(sweep->verdict)}, {"text", sweep->text}};
    fmt::print("{}\n", j.dump(1));
  } else {
    fmt::print("{}", io::formatSummaryText(summary));
    if (sweep)
      fmt::print("sweep check (recording.deskewed: auto): {}\n", sweep->text);
  }
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
