// taiga eval: trajectory accuracy metrics.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct EvalOptions {
  std::string estimate, reference;
  std::string align = "se3";
  bool json = false;
};
}  // namespace

Command addEvalCommand(CLI::App& tool) {
  auto options = std::make_shared<EvalOptions>();
  CLI::App* parser = tool.add_subcommand(
      "eval", "Compare an estimated trajectory with a reference (APE, RPE, drift, KITTI errors)");
  parser->add_option("--est", options->estimate, "Estimated trajectory (TUM or KITTI)")->required();
  parser->add_option("--ref", options->reference, "Reference trajectory (TUM or KITTI)")
      ->required();
  parser->add_option("--align", options->align, "Alignment before comparing")
      ->check(CLI::IsMember({"se3", "sim3", "origin", "none"}))
      ->capture_default_str();
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  return {parser, notImplemented("eval", "trajectory evaluation is issue 8"), options};
}

}  // namespace taiga::app
