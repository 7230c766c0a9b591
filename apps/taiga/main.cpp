// taiga: lidar-inertial mapping for forests. The command-line contract is in docs/cli.md.
#include <fmt/format.h>

#include <cstdio>
#include <exception>
#include <vector>

#include "command.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/version.hpp"

namespace taiga::app {

std::function<int()> notImplemented(std::string name, std::string planned_in) {
  return [name = std::move(name), planned_in = std::move(planned_in)] {
    fmt::print(stderr, "taiga {}: not implemented yet ({}).\n", name, planned_in);
    return static_cast<int>(kExitNotImplemented);
  };
}

namespace {

int runTool(int argc, char** argv) {
  CLI::App tool{"taiga: real-time lidar-inertial positioning and mapping for forests"};
  tool.set_version_flag("--version", fmt::format("taiga {}", kVersion));
  tool.require_subcommand(1);
  tool.fallthrough();
  bool verbose = false, quiet = false;
  tool.add_flag("-v,--verbose", verbose, "Print debug messages");
  tool.add_flag("-q,--quiet", quiet, "Print only warnings and errors");

  const std::vector<Command> commands{
      addSimulateCommand(tool),  addInfoCommand(tool),      addExportCommand(tool),
      addRegisterCommand(tool),  addRunCommand(tool),       addEvalCommand(tool),
      addCompareCommand(tool),   addGeorefCommand(tool),    addConfigCommand(tool),
      addExportMapCommand(tool), addCalibrateCommand(tool), addTreesCommand(tool),
      addViewCommand(tool),      addReplayCommand(tool)};

  try {
    tool.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = tool.exit(e);  // prints help, the version, or the parse error
    return code == 0 ? kExitOk : kExitBadInput;
  }
  if (verbose) setLogLevel(spdlog::level::debug);
  if (quiet) setLogLevel(spdlog::level::warn);

  for (const Command& command : commands) {
    if (command.parser->parsed()) return command.run();
  }
  return kExitBadInput;  // unreachable: require_subcommand(1)
}

}  // namespace
}  // namespace taiga::app

int main(int argc, char** argv) {
  using namespace taiga::app;
  try {
    return runTool(argc, argv);
  } catch (const taiga::InputError& e) {
    fmt::print(stderr, "taiga: error: {}\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "taiga: internal error: {}\nPlease report this with the command you ran.\n",
               e.what());
    return kExitInternalError;
  }
}
