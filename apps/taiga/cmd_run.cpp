// taiga run: lidar-inertial odometry over a recording, with the outputs of pipeline/run.hpp.
#include <fmt/format.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <cmath>
#include <csignal>
#include <memory>

#include "command.hpp"
#include "recording_options.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/config.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/pipeline/run.hpp"

namespace taiga::app {
namespace {

/// How the points' times were taken: said whenever they were not measured.
void printPointTimes(const pipeline::RunSummary& s) {
  using Verdict = pipeline::SweepCheck::Verdict;
  const Verdict verdict = s.sweep_check ? s.sweep_check->verdict : Verdict::kNotNeeded;
  if (verdict == Verdict::kDeskewedUpstream) {
    fmt::print("points     the clouds have no per-point times and were deskewed upstream, {}; "
               "every point was taken at the stamp (recording.deskewed: false if not)\n",
               s.sweep_check->text);
  } else if (verdict == Verdict::kRawSweep) {
    fmt::print("points     {} of {} scans had no per-point times; they were made up from the "
               "azimuth, the sweep check found {}\n",
               s.scans_with_made_up_times, s.scans, s.sweep_check->text);
  } else if (s.scans_with_made_up_times > 0) {
    fmt::print(
        "points     {} of {} scans had no per-point times; they were made up from the azimuth "
        "and the scans deskewed with them{}. Clouds deskewed upstream are then deskewed twice "
        "(smeared by the motion over a sweep, 20-27 cm on a walk, health still ok): set "
        "recording.deskewed: true for them (docs/recordings.md)\n",
        s.scans_with_made_up_times, s.scans,
        verdict == Verdict::kUndecided ? fmt::format("; the sweep check was {}", s.sweep_check->text)
                                       : "");
  }
}
struct RunOptions {
  std::string recording, config, out;
  bool realtime = false;
  bool live = false;
  bool ply = false;
  double map_voxel_m = 0.0;
  int threads = -1;  // -1: compute.threads
  std::string registration;
  std::string moving_boxes;
  std::string view;
};

// One malloc arena for the whole run. Each loop closure attempt allocates tens of MB for a
// moment (the candidate's submap, its NDT cells); in a thread arena of its own glibc keeps that
// high-water mark, and the run's resident memory kept growing with every attempt (0.04-0.13 MB
// per keyframe on handheld-long). With one arena the freed blocks are reused by every thread:
// handheld-long (900 s, 64 beams) stays flat, at the same outputs and speed (bench/BENCHMARK.md,
// "Session 16").
void useOneMallocArena() {
#ifdef __GLIBC__
  mallopt(M_ARENA_MAX, 1);
#endif
}

// A lost track's consequences: which map segments float, whether the run ended lost.
void printLostTrack(const pipeline::HealthReport& h) {
  const std::vector<std::uint64_t> floating = h.floatingSegments();
  for (const std::uint64_t segment : floating)
    fmt::print(
        "           map segment {0} never found in the map: it stays where dead reckoning put it, "
        "not tied to the map, and its keyframes are in map_segment_{0}.las, not map.las\n",
        segment);
  if (!floating.empty() && !h.ended_lost && floating.back() + 1 < h.map_segments)
    fmt::print("           the later segments are tied to the map again\n");
  if (h.ended_lost) fmt::print("           the run ended lost: its last scans are not trusted\n");
  fmt::print("           scans.csv marks every scan (exit code 3)\n");
}

// The health monitor's verdict; the first lost stretch with its reason, since that is where a
// user looks first.
void printHealth(const pipeline::HealthReport& h) {
  fmt::print("health     {}: {} scans ok, {} degraded, {} lost; {} map segment{}\n", h.verdict(),
             h.ok, h.degraded, h.lost, h.map_segments, h.map_segments == 1 ? "" : "s");
  constexpr int kListed = 5;  // summary.json has them all
  int listed = 0;
  for (const pipeline::HealthStretch& stretch : h.stretches) {
    if (stretch.status != "lost") continue;
    if (listed++ == kListed) break;
    fmt::print("           lost {:.1f}..{:.1f} s ({} scans): {}\n", stretch.from_s, stretch.to_s,
               stretch.scans, stretch.reason);
  }
  if (h.sparse_scans > 0)
    fmt::print(
        "           {} sparse scans (lost packets or a blocked view), the first {:.1f}..{:.1f} s: "
        "{}\n",
        h.sparse_scans, h.sparse.front().from_s, h.sparse.front().to_s, h.sparse.front().reason);
  if (std::isfinite(h.median_innovation_deg))
    fmt::print(
        "           IMU prediction vs registration: {:.2f} deg, {:.3f} m per scan (median){}\n",
        h.median_innovation_deg, h.median_innovation_m,
        h.calibration_suspect
            ? ": too far apart, the extrinsic rotation, time offset or IMU noise settings "
              "are suspect (docs/odometry.md, Health); taiga calibrate or calibration.at_start "
              "estimates the first two (docs/calibration.md)"
            : "");
  for (const pipeline::Reattachment& r : h.reattached)
    fmt::print(
        "           map segment {} re-attached to the map at {:.1f} s: {:.2f} m / {:.2f} deg from "
        "dead reckoning, {:.0f} % of its points above the ground on the map\n",
        r.segment, r.t_s, r.correction_m, r.correction_deg, 100.0 * r.overlap);
  if (h.trackLost()) printLostTrack(h);
}

void printCalibration(const pipeline::CalibrationRunReport& c) {
  if (!c.skipped.empty()) {
    fmt::print("calibrate  skipped, the configured rig is used: {}\n", c.skipped);
    return;
  }
  fmt::print(
      "calibrate  {} passes in {:.0f} s: lidar time offset {:.2f} ms ({:+.2f} ms, 1-sigma {:.2f} "
      "ms{}), R_body_lidar changed by {:.3f} deg (observable about: {})\n",
      c.passes, c.wall_time_s, 1e3 * c.time_offset_s, 1e3 * c.offset_change_s,
      1e3 * c.offset_sigma_s, c.offset_observable ? "" : ", not observable: kept",
      c.rotation_change_deg,
      c.rotation_observable_axes.empty() ? "none" : c.rotation_observable_axes);
  if (!c.advice.empty()) fmt::print("           {}\n", c.advice);
  if (c.lever_arm_sigma_m.any())
    fmt::print(
        "           lever arm change {:.1f} {:.1f} {:.1f} cm (1-sigma {:.1f} {:.1f} {:.1f} cm), "
        "applied along: {}\n",
        100 * c.lever_arm_change_m.x(), 100 * c.lever_arm_change_m.y(),
        100 * c.lever_arm_change_m.z(), 100 * c.lever_arm_sigma_m.x(),
        100 * c.lever_arm_sigma_m.y(), 100 * c.lever_arm_sigma_m.z(),
        c.lever_arm_applied_axes.empty() ? "none" : c.lever_arm_applied_axes);
  if (!c.gyro_noise_text.empty())
    fmt::print("           {}{}\n", c.gyro_noise_text,
               c.gyro_noise_applied ? " (applied for this run: calibration.apply_gyro_noise)" : "");
}

// Ctrl-C and SIGTERM end a live run cleanly: the packet streams end, the run finishes and writes
// every output. A second signal kills the process as usual.
void stopLiveOnSignal(int signal) {
  io::ouster::requestLiveStop();
  std::signal(signal, SIG_DFL);
}

void printLive(const io::ouster::LiveStats& l) {
  fmt::print(
      "live       {} lidar and {} IMU packets; {} frames, {} incomplete ({} columns missing: lost "
      "packets), {} bad packets, {} other datagrams, {} dropped by the kernel; ended: {}\n",
      l.lidar_packets, l.imu_packets, l.frames, l.incomplete_frames, l.missing_columns,
      l.bad_packets, l.other_datagrams, l.kernel_drops, l.stop_reason);
}

int run(const RunOptions& options) {
  useOneMallocArena();
  SystemConfig config = loadConfig(options.config);
  if (!options.registration.empty()) config.odometry.method = options.registration;
  if (options.threads >= 0) config.compute.threads = options.threads;
  validateAll(config);
  if (options.live == !options.recording.empty())
    throw InputError("taiga run: give either a RECORDING or --live, not both or neither");
  if (options.live && options.realtime)
    throw InputError("taiga run: --realtime replays a recording at sensor rate; --live is live");
  const pipeline::RunOptions run_options{.out_dir = options.out,
                                         .write_ply = options.ply,
                                         .map_voxel_m = options.map_voxel_m,
                                         .realtime = options.realtime,
                                         .moving_boxes_file = options.moving_boxes,
                                         .view = options.view};
  if (options.live) {
    std::signal(SIGINT, stopLiveOnSignal);
    std::signal(SIGTERM, stopLiveOnSignal);
  }
  const pipeline::RunSummary s =
      options.live ? pipeline::runLive(config, run_options)
                   : pipeline::runOdometry(options.recording, config, run_options);
  if (s.calibration) printCalibration(*s.calibration);
  fmt::print("scans      {} read, {} processed; {} IMU samples; {:.1f} s, {:.1f} m of path\n",
             s.scans, s.scans_processed, s.imu_samples, s.duration_s, s.path_length_m);
  fmt::print("lidar      lidar factors {} rejected, {} inflated; {} keyframes, {} map points\n",
             s.lidar_rejected, s.lidar_inflated, s.keyframes, s.map_points);
  printPointTimes(s);
  printHealth(s.health);
  fmt::print(
      "time       {:.1f} ms median, {:.1f} ms p95, {:.1f} ms p99, {:.1f} ms max per scan on {} "
      "thread{}; {}; peak memory {:.0f} MB\n",
      s.median_ms, s.p95_ms, s.p99_ms, s.max_ms, s.threads, s.threads == 1 ? "" : "s",
      s.live ? "live" : fmt::format("{:.2f}x real time", s.realtime_factor), s.peak_memory_mb);
  fmt::print("mapping    {} loop closures (loops.csv); map exported in {:.1f} s after the run\n",
             s.loop_closures, s.map_export_s);
  if (s.trees)
    fmt::print(
        "trees      {} stems in trees.csv (the live list: {} updates, {:.1f} CPU-s at idle "
        "priority during the run; the final inventory {:.1f} s after it)\n",
        *s.trees, s.trees_updates, s.trees_work_s, s.trees_final_s);
  if (s.streams)
    fmt::print(
        "streams    {} poses sent; Foxglove: {} clients, {} messages ({} dropped for a client too "
        "far behind)\n",
        s.streams->poses_sent, s.streams->foxglove_clients, s.streams->foxglove_messages,
        s.streams->foxglove_dropped);
  if (s.live) printLive(*s.live);
  if (s.realtime)  // --realtime and --live alike
    fmt::print(
        "realtime   {} scans dropped (odometry behind); latency {:.1f} ms p50, {:.1f} ms p95, "
        "{:.1f} ms p99, {:.1f} ms max from a scan's delivery to its pose\n",
        s.realtime->dropped_scans, s.realtime->latency_p50_ms, s.realtime->latency_p95_ms,
        s.realtime->latency_p99_ms, s.realtime->latency_max_ms);
  if (s.georef) {
    if (s.georef->skipped.empty()) {
      fmt::print(
          "georef     {} of {} GNSS fixes ({}), residual {:.2f} m horizontal; 1-sigma {:.2f} m "
          "east, {:.2f} m north, {:.2f} deg yaw; EPSG:{} in georef/\n",
          s.georef->inliers, s.georef->fixes, s.georef->method, s.georef->horizontal_rms_m,
          s.georef->sigma[0], s.georef->sigma[1], s.georef->sigma[5] * kDegPerRad, s.georef->epsg);
    } else {
      fmt::print("georef     not georeferenced: {}\n", s.georef->skipped);
    }
  }
  fmt::print(
      "outputs    {}/ (trajectory.tum, trajectory_imu.tum, trajectory_odometry.tum, keyframes.tum, "
      "keyframes/, map.las{}, loops.csv, timing.csv, scans.csv, summary.json{})\n",
      options.out, options.ply ? ", map.ply" : "",
      s.georef && s.georef->skipped.empty() ? ", georef/" : "");
  return s.health.trackLost() ? kExitTrackLost : kExitOk;
}

}  // namespace

Command addRunCommand(CLI::App& tool) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* parser = tool.add_subcommand(
      "run", "Estimate the trajectory and build the forest map from a recording");
  parser->add_option("RECORDING", options->recording, "ROS1 bag, Ouster pcap or folder");
  addConfigOption(*parser, options->config);
  parser->add_option("--out", options->out, "Output directory")->required();
  parser->add_flag("--realtime", options->realtime,
                   "Replay at sensor rate as a live sensor would deliver it: scans are dropped "
                   "when more than 2 wait, and dropped scans and latency are reported");
  parser->add_flag("--live", options->live,
                   "Run on a live Ouster sensor's UDP packets (configuration section live:) "
                   "instead of a recording, until Ctrl-C or live.idle_timeout_s without a packet");
  parser->add_option("--view", options->view,
                     "Serve the web viewer at HOST:PORT while the run goes (open "
                     "http://HOST:PORT/); the Foxglove channels are on the same port, instead "
                     "of live.foxglove (docs/viewer.md)");
  parser->add_flag("--ply", options->ply, "Also write map.ply");
  parser
      ->add_option("--threads", options->threads,
                   "Worker threads of the parallel stages, 0: one per core (overrides "
                   "compute.threads)")
      ->check(CLI::Range(0, 1024));
  parser
      ->add_option("--registration", options->registration,
                   "Scan-to-map registration (overrides odometry.method)")
      ->check(CLI::IsMember({"ndt", "d2d", "gicp"}));
  parser
      ->add_option("--map-voxel", options->map_voxel_m,
                   "Decimate the map to one point per voxel of this size, m")
      ->check(CLI::NonNegativeNumber);
  parser
      ->add_option("--moving-boxes", options->moving_boxes,
                   "CSV of per-scan boxes (body frame) around moving parts of the rig, e.g. a "
                   "harvester's boom; returns inside are dropped (docs/recordings.md)")
      ->check(CLI::ExistingFile);
  return {parser, [options] { return run(*options); }, options};
}

}  // namespace taiga::app
