// taiga eval: trajectory accuracy metrics (docs/evaluation.md).
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>

#include "command.hpp"
#include "simulated_scene.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/eval/map_sharpness.hpp"
#include "taiga/eval/plot.hpp"
#include "taiga/eval/report.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/trees/tree_files.hpp"

namespace taiga::app {
namespace {

// alignWithOrientations' lever: an orientation counts as much as positions this far apart. Against
// a walk's metres of extent that leaves Umeyama's rotation as it is; along a straight path it is
// the only thing that fixes the rotation about it.
constexpr double kMapAlignmentLever_m = 0.1;
struct EvalOptions {
  std::string estimate, reference;
  std::string align = "se3";
  int rpe_delta = 1;
  std::optional<double> rpe_delta_m;
  bool rotation = false;
  double t_max_diff_s = 0.01;
  double t_offset_s = 0.0;
  std::string timing;
  std::string scans;
  double scan_period_s = 0.1;
  std::string plots;
  bool distance = false;
  double distance_bin_m = 0.1;
  bool json = false;
  bool markdown = false;
  std::string map, scene;
  double map_cap_m = 1.0;
  std::size_t map_points = 200000;
  std::string trees, ref_trees;
  eval::TreeAccuracyOptions tree_options;
};

// Map sharpness: an evenly strided subsample of the map, moved into the truth frame with the
// trajectory's alignment, against the regenerated scene.
eval::MapSharpness mapSharpness(const EvalOptions& options, const eval::AlignmentTransform& T) {
  io::LasReader reader(options.map);
  const std::uint64_t stride = std::max<std::uint64_t>(
      1, (reader.pointCount() + options.map_points - 1) / options.map_points);
  const PointCloud sample = reader.readStrided(stride);
  const sim::Simulation simulation = simulationOfRecording(options.scene);
  const sim::Scene& scene = simulation.scene();
  return eval::computeMapSharpness(sample.positions, reader.pointCount(), T,
                                   [&](const Eigen::Vector3d& p_ref, double max_m) {
                                     return scene.distanceToSurface(p_ref, max_m);
                                   },
                                   {.cap_m = options.map_cap_m, .max_points = options.map_points});
}

int runEval(const EvalOptions& options) {
  eval::EvalReport report;
  report.est_file = options.estimate;
  report.ref_file = options.reference;
  report.show_distance = options.distance;
  eval::EvalOptions& o = report.options;
  o.association = {options.t_max_diff_s, options.t_offset_s};
  o.alignment = eval::parseAlignment(options.align);
  o.rotation = options.rotation;
  o.rpe_delta_frames = static_cast<std::size_t>(options.rpe_delta);
  o.rpe_delta_m = options.rpe_delta_m;
  o.distance_bin_m = options.distance_bin_m;

  const Trajectory est = io::readTrajectory(options.estimate);
  const Trajectory ref = io::readTrajectory(options.reference);
  try {
    report.result = eval::evaluate(est, ref, o);
  } catch (const InputError& e) {
    throw InputError(
        fmt::format("{} against {}: {}", options.estimate, options.reference, e.what()));
  }
  // The map and its trees hang on the trajectory at a lever arm of metres: with se3, their
  // alignment takes the orientations too, so that a short, straight path (the harvester's strip
  // road) does not leave the rotation about it to chance (eval/alignment.hpp).
  const eval::AlignmentTransform map_transform =
      report.result.alignment == eval::Alignment::kSe3
          ? eval::alignWithOrientations(report.result.pairs.est, report.result.pairs.ref,
                                        kMapAlignmentLever_m)
          : report.result.transform;
  if (!options.map.empty() || !options.scene.empty()) {
    if (options.map.empty() || options.scene.empty())
      throw InputError(
          "--map and --scene go together: the map and the simulated recording whose "
          "scene it is scored against");
    report.map_file = options.map;
    report.scene_dir = options.scene;
    report.map_sharpness = mapSharpness(options, map_transform);
  }
  if (!options.trees.empty() || !options.ref_trees.empty()) {
    if (options.trees.empty() || options.ref_trees.empty())
      throw InputError("--trees and --ref-trees go together: a tree list and the reference one");
    report.trees_file = options.trees;
    report.ref_trees_file = options.ref_trees;
    std::vector<Eigen::Vector3d> path_m;
    for (const StampedPose& pose : ref) path_m.push_back(pose.pose.translation());
    report.trees = eval::evaluateTrees(trees::readTreesCsv(options.trees),
                                       trees::readTreesCsv(options.ref_trees), map_transform,
                                       path_m, options.tree_options);
  }
  if (!options.scans.empty()) {
    report.scans_file = options.scans;
    const std::vector<eval::ScanStatusAt> scans = eval::readScanStatuses(options.scans);
    report.ape_by_status = eval::apeByStatus(report.result, scans);
    const Trajectory ok = eval::posesWithStatus(est, scans, "ok");
    if (report.ape_by_status->size() > 1 && ok.size() >= 3) {
      try {
        const eval::EvalResult alone = eval::evaluate(ok, ref, o);
        report.ok_self_aligned =
            eval::StatusApe{"ok", alone.ape.translation_error_m.size(),
                            alone.ape.translation_m.rmse, alone.ape.translation_m.max};
      } catch (const InputError&) {
        // Too few or too straight a stretch of ok poses to align alone: the split above stands.
      }
    }
  }
  if (!options.timing.empty()) {
    report.timing_file = options.timing;
    report.timing_table = eval::readTimingCsv(options.timing);
    report.timing = eval::computeTimingStatistics(*report.timing_table, options.scan_period_s);
  }

  if (options.json)
    fmt::print("{}", eval::formatEvalJson(report));
  else if (options.markdown)
    fmt::print("{}", eval::formatEvalMarkdown(report));
  else
    fmt::print("{}", eval::formatEvalText(report));
  std::fflush(stdout);

  if (!options.plots.empty()) {
    const eval::PlotOutcome plots =
        eval::makePlots(eval::formatEvalPlotData(report), options.plots, "eval_plot_data.json");
    if (!plots.ok) {
      fmt::print(stderr, "taiga eval: {}\n", plots.message);
      return kExitFailure;
    }
    for (const auto& file : plots.files) fmt::print(stderr, "wrote {}\n", file.string());
  }
  return kExitOk;
}
}  // namespace

Command addEvalCommand(CLI::App& tool) {
  auto options = std::make_shared<EvalOptions>();
  CLI::App* parser = tool.add_subcommand(
      "eval", "Compare an estimated trajectory with a reference (APE, RPE, drift, KITTI errors)");
  parser->add_option("--est", options->estimate, "Estimated trajectory (TUM or KITTI)")->required();
  parser->add_option("--ref", options->reference, "Reference trajectory (TUM or KITTI)")
      ->required();
  parser
      ->add_option("--align", options->align,
                   "Alignment before comparing (evo: -a, -as, --align_origin)")
      ->check(CLI::IsMember({"se3", "sim3", "origin", "none"}))
      ->capture_default_str();
  parser
      ->add_option("--rpe-delta", options->rpe_delta,
                   "RPE delta in frames (evo --delta N --delta_unit f)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser
      ->add_option("--rpe-delta-m", options->rpe_delta_m,
                   "Also RPE over this many metres of path (evo --delta D --delta_unit m)")
      ->check(CLI::PositiveNumber);
  parser->add_flag("--rotation", options->rotation,
                   "Also the rotation errors, in degrees (evo -r angle_deg)");
  parser
      ->add_option("--t-max-diff", options->t_max_diff_s,
                   "Largest time difference of associated poses, s (evo --t_max_diff)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  parser
      ->add_option("--t-offset", options->t_offset_s,
                   "Added to the estimate's times before associating, s (evo --t_offset)")
      ->capture_default_str();
  parser->add_option("--timing", options->timing,
                     "timing.csv of the run: processing time statistics");
  parser->add_option("--scans", options->scans,
                     "scans.csv of the run: the APE of the poses of ok, degraded and lost scans "
                     "apart (docs/odometry.md, Health)");
  parser
      ->add_option("--scan-period-s", options->scan_period_s,
                   "Sensor period for the timing statistics, s")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--plots", options->plots, "Write PNG plots into this directory");
  parser->add_flag("--distance", options->distance,
                   "Show the distance distribution between the two trajectories (unaligned)");
  parser->add_option("--distance-bin-m", options->distance_bin_m, "Histogram bin width, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser
      ->add_option("--map", options->map,
                   "map.las of the run: score its distance to the true scene (with --scene)")
      ->check(CLI::ExistingFile);
  parser
      ->add_option("--scene", options->scene,
                   "Directory written by taiga simulate (scenario.yaml, scene.json) whose scene "
                   "the map is scored against")
      ->check(CLI::ExistingDirectory);
  parser->add_option("--map-cap", options->map_cap_m, "Map distances are capped here, m")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--map-points", options->map_points, "Score at most this many map points")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser->add_option("--trees", options->trees,
                     "A tree list (trees.csv of `taiga trees`) to score against --ref-trees");
  parser->add_option("--ref-trees", options->ref_trees,
                     "The reference tree list (e.g. a simulated recording's trees.csv)");
  parser
      ->add_option("--trees-radius", options->tree_options.max_path_distance_m,
                   "Trees within this distance of the reference path are counted, m")
      ->check(CLI::PositiveNumber);
  parser
      ->add_option("--trees-min-dbh", options->tree_options.min_dbh_m,
                   "Reference trees at least this thick are counted, m")
      ->check(CLI::NonNegativeNumber);
  parser
      ->add_option("--trees-match", options->tree_options.match_m,
                   "A stem and a reference tree match within this distance, m")
      ->check(CLI::PositiveNumber);
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  parser->add_flag("--markdown", options->markdown, "Print Markdown tables instead of text");
  return {parser, [options] { return runEval(*options); }, options};
}

}  // namespace taiga::app
