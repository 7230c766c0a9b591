// taiga export: decoded scans as point-cloud files, to look at what taiga reads before running.
#include <fmt/format.h>

#include <memory>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/progress.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/io/las_writer.hpp"
#include "taiga/io/recording_summary.hpp"

namespace taiga::app {
namespace {
struct ExportOptions {
  std::string recording;
  std::string config;
  int scan = -1;
  bool all = false;
  std::string out;
  std::string format = "ply";
};

void writeScan(const io::Scan& scan, const std::filesystem::path& path) {
  if (path.extension() == ".las") {
    io::LasWriter writer(path);
    writer.append(scan.cloud_in_lidar);
    writer.close();
  } else {
    io::writePly(path, scan.cloud_in_lidar);
  }
}

int runExport(const ExportOptions& options) {
  if (!options.all && options.scan < 0) throw InputError("give --scan N or --all");
  const std::filesystem::path out = options.out;
  if (!options.all && out.extension() != ".ply" && out.extension() != ".las") {
    throw InputError(fmt::format("--out {}: expected a .ply or .las file name", options.out));
  }
  if (options.all) std::filesystem::create_directories(out);

  const SystemConfig config = loadConfig(options.config);
  io::Recording recording = io::openRecording(options.recording, config.recording, config.rig);
  const auto announced = io::announcedScanCount(options.recording, config.recording);
  Progress progress("exporting", announced.value_or(0), "scans", stderr, options.all && announced && isatty(fileno(stderr)));
  std::size_t written = 0;
  while (auto event = recording.next()) {
    const auto* scan = std::get_if<io::Scan>(&*event);
    if (!scan) continue;
    if (options.all) {
      writeScan(*scan, out / fmt::format("scan_{:06}.{}", scan->index, options.format));
      progress.update(++written);
    } else if (scan->index == static_cast<std::uint64_t>(options.scan)) {
      writeScan(*scan, out);
      fmt::print("wrote scan {} ({} points, {:.6f} .. {:.6f} s) to {}\n", scan->index, scan->cloud_in_lidar.size(),
                 scan->t_start_s, scan->t_end_s, out.string());
      return kExitOk;
    }
  }
  progress.finish();
  if (!options.all) {
    throw InputError(fmt::format("{}: has no scan {} (scans are numbered from 0)", options.recording, options.scan));
  }
  fmt::print("wrote {} scans to {}\n", written, out.string());
  return kExitOk;
}
}  // namespace

Command addExportCommand(CLI::App& tool) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* parser = tool.add_subcommand(
      "export", "Write decoded scans (points in the lidar frame with time, intensity, ring) as PLY or LAS");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder")->required();
  auto* scan = parser->add_option("--scan", options->scan, "Index of the scan to export, from 0")->check(CLI::NonNegativeNumber);
  auto* all = parser->add_flag("--all", options->all, "Export every scan into the directory --out");
  scan->excludes(all);
  parser->add_option("--out", options->out, "Output .ply or .las file (--scan) or directory (--all)")->required();
  parser->add_option("--format", options->format, "File format with --all")
      ->check(CLI::IsMember({"ply", "las"}))
      ->capture_default_str();
  addConfigOption(*parser, options->config);
  return {parser, [options] { return runExport(*options); }, options};
}

}  // namespace taiga::app
