// taiga georef: put a finished trajectory into a national coordinate system.
#include <memory>

#include "command.hpp"

namespace taiga::app {
namespace {
struct GeorefOptions {
  std::string trajectory, gnss, out;
  std::string method = "robust";
};
}  // namespace

Command addGeorefCommand(CLI::App& tool) {
  auto options = std::make_shared<GeorefOptions>();
  CLI::App* parser = tool.add_subcommand(
      "georef", "Fit a trajectory to GNSS fixes and write it in a projected coordinate system");
  parser->add_option("--traj", options->trajectory, "Trajectory to georeference (TUM)")->required();
  parser->add_option("--gnss", options->gnss, "Recording or CSV file with GNSS fixes")->required();
  parser->add_option("--method", options->method, "Fitting method")
      ->check(CLI::IsMember({"closed", "pf3", "pf6", "robust"}))
      ->capture_default_str();
  parser->add_option("--out", options->out, "Output directory")->required();
  return {parser, notImplemented("georef", "georeferencing is issue 9"), options};
}

}  // namespace taiga::app
