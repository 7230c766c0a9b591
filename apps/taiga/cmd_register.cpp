// taiga register: align two point clouds.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct RegisterOptions {
  std::string source, target, guess;
  std::string method = "ndt";
  double resolution_m = 1.0;
  bool json = false;
};
}  // namespace

Command addRegisterCommand(CLI::App& tool) {
  auto options = std::make_shared<RegisterOptions>();
  CLI::App* parser = tool.add_subcommand(
      "register", "Align SOURCE to TARGET and print T_target_source, fitness, iterations and time");
  parser->add_option("SOURCE", options->source, "Point cloud to move (PCD or PLY)")->required();
  parser->add_option("TARGET", options->target, "Point cloud to align to (PCD or PLY)")->required();
  parser->add_option("--method", options->method, "Registration method")
      ->check(CLI::IsMember({"ndt", "d2d", "gicp"}))
      ->capture_default_str();
  parser->add_option("--guess", options->guess, "Initial T_target_source (4x4 matrix text file)");
  parser->add_option("--resolution", options->resolution_m, "NDT cell size, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  return {parser, notImplemented("register", "scan registration is issue 5"), options};
}

}  // namespace taiga::app
