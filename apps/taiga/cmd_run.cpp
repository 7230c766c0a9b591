// taiga run: lidar-inertial SLAM over a recording.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct RunOptions {
  std::string recording, config, out;
  bool realtime = false;
};
}  // namespace

Command addRunCommand(CLI::App& tool) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* parser = tool.add_subcommand(
      "run", "Estimate the trajectory and build the forest map from a recording");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")
      ->required();
  parser->add_option("--config", options->config, "YAML configuration (see `taiga config`)");
  parser->add_option("--out", options->out, "Output directory")->required();
  parser->add_flag("--realtime", options->realtime, "Play the recording at sensor rate");
  return {parser, notImplemented("run", "the odometry pipeline is issue 6, mapping issue 7"),
          options};
}

}  // namespace taiga::app
