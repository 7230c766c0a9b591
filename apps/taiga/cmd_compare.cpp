// taiga compare: one table and one plot over several runs.
#include <memory>
#include <vector>

#include "command.hpp"

namespace taiga::app {
namespace {
struct CompareOptions {
  std::vector<std::string> runs;
  std::string reference;
};
}  // namespace

Command addCompareCommand(CLI::App& tool) {
  auto options = std::make_shared<CompareOptions>();
  CLI::App* parser = tool.add_subcommand(
      "compare", "Tabulate and plot the accuracy of several runs against one reference");
  parser->add_option("RUN_DIR", options->runs, "Output directories of `taiga run`")->required();
  parser->add_option("--ref", options->reference, "Reference trajectory (TUM or KITTI)")
      ->required();
  return {parser, notImplemented("compare", "run comparison is issue 8"), options};
}

}  // namespace taiga::app
