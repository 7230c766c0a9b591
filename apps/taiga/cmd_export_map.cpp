// taiga export-map: the forest map again from a finished run's keyframes/ directory (its scans
// and final poses), e.g. with another --map-voxel, without re-running the odometry.
#include <fmt/format.h>

#include <memory>

#include "command.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/map_export.hpp"

namespace taiga::app {
namespace {
struct ExportMapOptions {
  std::string keyframes_dir, out;
  double map_voxel_m = 0.0;
  bool ply = false;
};

int runExportMap(const ExportMapOptions& options) {
  const mapping::KeyframeStore store = mapping::KeyframeStore::open(options.keyframes_dir);
  const mapping::MapExportSummary s = mapping::exportMap(
      store, store.poses(), options.out, {.voxel_m = options.map_voxel_m, .write_ply = options.ply});
  fmt::print("map        {} keyframes, {} points read, {} written to {}{}\n", s.keyframes,
             s.points_read, s.points_written, options.out,
             options.ply ? " (and .ply)" : "");
  return kExitOk;
}
}  // namespace

Command addExportMapCommand(CLI::App& tool) {
  auto options = std::make_shared<ExportMapOptions>();
  CLI::App* parser = tool.add_subcommand(
      "export-map", "Write the map again from a run's keyframes/ directory (scans and poses)");
  parser->add_option("KEYFRAMES_DIR", options->keyframes_dir, "The keyframes/ directory of a run")
      ->required()
      ->check(CLI::ExistingDirectory);
  parser->add_option("--out", options->out, "Output LAS file (map.ply next to it with --ply)")
      ->required();
  parser
      ->add_option("--map-voxel", options->map_voxel_m,
                   "Decimate the map to one point per voxel of this size, m")
      ->check(CLI::NonNegativeNumber);
  parser->add_flag("--ply", options->ply, "Also write the map as PLY");
  return {parser, [options] { return runExportMap(*options); }, options};
}

}  // namespace taiga::app
