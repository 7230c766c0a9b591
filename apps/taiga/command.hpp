#pragma once
// One subcommand of the `taiga` tool: its CLI11 parser and the function that runs it.
// Each subcommand lives in its own cmd_<name>.cpp and is added to the tool in main.cpp.

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

namespace taiga::app {

/// Exit codes of the tool, documented in README.md.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,   ///< the work itself failed (e.g. a run diverged)
  kExitBadInput = 2,  ///< bad command line, file or configuration; the message says which
  /// taiga run finished and wrote every output, but lost track and did not re-attach to the
  /// map (summary.json health); taiga register's answer is not to be trusted (--strict)
  kExitTrackLost = 3,
  kExitNotImplemented = 69,  ///< the subcommand exists in the contract but is not built yet
  kExitInternalError = 70,   ///< a bug in taiga; please report it with the message
};

struct Command {
  CLI::App* parser = nullptr;
  std::function<int()> run;
  /// The parsed option values, which `parser` writes into: kept alive as long as the command.
  std::shared_ptr<const void> options;
};

/// A run function for a subcommand that is part of the command-line contract but not built yet:
/// it says so on standard error and exits with kExitNotImplemented.
std::function<int()> notImplemented(std::string name, std::string planned_in);

Command addSimulateCommand(CLI::App& tool);
Command addInfoCommand(CLI::App& tool);
Command addExportCommand(CLI::App& tool);
Command addRegisterCommand(CLI::App& tool);
Command addRunCommand(CLI::App& tool);
Command addEvalCommand(CLI::App& tool);
Command addCompareCommand(CLI::App& tool);
Command addGeorefCommand(CLI::App& tool);
Command addConfigCommand(CLI::App& tool);
Command addExportMapCommand(CLI::App& tool);
Command addCalibrateCommand(CLI::App& tool);
Command addReplayCommand(CLI::App& tool);
Command addTreesCommand(CLI::App& tool);
Command addViewCommand(CLI::App& tool);

}  // namespace taiga::app
