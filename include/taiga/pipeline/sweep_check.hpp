#pragma once
// Was a cloud without per-point times deskewed upstream, or is it a raw sweep? (recording.deskewed:
// auto, docs/recordings.md "Per-point times, and clouds deskewed upstream").
//
// A spinning lidar's first and last firings of a sweep are a sweep period apart in time but side
// by side in space: at the seam between them a surface is seen twice, from the poses at the
// sweep's start and at its end. In a raw sweep the two views disagree by the motion over the
// sweep and agree once the sweep is deskewed; in a cloud deskewed upstream they already agree,
// and a second deskew tears them apart by that motion. The rest of a scan cannot tell the two
// apart (a smooth distortion registers well against a map built of scans distorted alike), the
// seam can. The check measures the seam both ways over the recording's first seconds: as given,
// and with the sweep's rotation from the gyro taken out (rotation only: the gyro needs no
// velocity estimate, and a rotation of a degree moves the ground at the seam by centimetres).

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include "taiga/core/system_config.hpp"

namespace taiga::pipeline {

/// The seam's disagreement: the median distance of the points of a sweep's last firings to the
/// local planes of its first ones, m. `sweep_fraction` is each point's place in the sweep (0 at
/// the first firing, 1 at the last). Empty when fewer than `min_pairs` points found a plane.
std::optional<double> seamMismatch_m(std::span<const Eigen::Vector3d> positions,
                                     std::span<const double> sweep_fraction,
                                     std::size_t min_pairs = 30);

struct SweepCheck {
  enum class Verdict { kNotNeeded, kRawSweep, kDeskewedUpstream, kUndecided };
  Verdict verdict = Verdict::kNotNeeded;
  std::size_t scans_read = 0;
  std::size_t scans_used = 0;  ///< turned enough over their sweep and had a seam to measure
  /// Median over the used scans of log(seam as given / seam with the gyro's rotation taken out):
  /// below zero the cloud agrees with itself as given (deskewed upstream), above a raw sweep.
  double median_log_ratio = 0.0;
  std::string text;  ///< one line for the log and summary.json
};

std::string toString(SweepCheck::Verdict verdict);

struct SweepCheckOptions {
  /// Scans that turned enough to be judged: read until this many are found...
  std::size_t enough_scans = 100;
  /// ... or this much of the recording is read (a harvester that drives straight may never turn).
  double max_duration_s = 60.0;
};

/// The check over the start of `recording` with `config`'s rig; kNotNeeded when its scans carry
/// per-point times, kUndecided when no IMU reading arrives (nothing to measure the turn by).
/// Throws InputError on unreadable input, as opening the recording does.
SweepCheck checkSweeps(const std::filesystem::path& recording, const SystemConfig& config,
                       const SweepCheckOptions& options = {});

/// recording.deskewed: auto, resolved before a run or a calibration reads the recording: the
/// check, its verdict logged, and recording.deskewed set to true in `config` when the clouds were
/// deskewed upstream (a raw or undecided verdict keeps the made-up times, with a warning when
/// undecided). Empty when recording.deskewed is set by the user.
std::optional<SweepCheck> resolveDeskewed(const std::filesystem::path& recording,
                                          SystemConfig& config);

}  // namespace taiga::pipeline
