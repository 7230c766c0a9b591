// taiga export: decoded scans as point-cloud files.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct ExportOptions {
  std::string recording;
  int scan = -1;
  bool all = false;
  std::string out;
};
}  // namespace

Command addExportCommand(CLI::App& tool) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* parser =
      tool.add_subcommand("export", "Write decoded scans of a recording as PLY or LAS");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")
      ->required();
  auto* scan = parser->add_option("--scan", options->scan, "Index of the scan to export")
                   ->check(CLI::NonNegativeNumber);
  auto* all = parser->add_flag("--all", options->all, "Export every scan into the directory --out");
  scan->excludes(all);
  parser->add_option("--out", options->out, "Output file (--scan) or directory (--all)")
      ->required();
  return {parser, notImplemented("export", "recording readers are issue 3"), options};
}

}  // namespace taiga::app
