// taiga info: what a recording contains.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct InfoOptions {
  std::string recording;
  bool json = false;
};
}  // namespace

Command addInfoCommand(CLI::App& tool) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* parser = tool.add_subcommand(
      "info", "Show the topics, rates, point fields and duration of a recording");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")
      ->required();
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  return {parser, notImplemented("info", "recording readers are issue 3"), options};
}

}  // namespace taiga::app
