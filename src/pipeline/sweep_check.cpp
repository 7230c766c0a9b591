#include "taiga/pipeline/sweep_check.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>
#include <vector>

#include "scan_preparation.hpp"
#include "taiga/calib/time_rotation.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/log.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/registration/kdtree.hpp"

namespace taiga::pipeline {
namespace {

/// The share of the sweep on either side of the seam that is compared: 30 deg of azimuth, wider
/// than the azimuths one column's beams fire at (the OS0's stagger spreads them over 18 deg,
/// and the times made up from the azimuth with them), so that both wedges hold every beam.
constexpr double kWedge = 1.0 / 12.0;
/// A scan counts when the gyro turned it by at least this over its sweep: below, both ways of
/// reading the seam agree within its roughness.
constexpr double kMinSweepTurn_rad = 0.3 * kRadPerDeg;
/// The verdict needs this many scans that turned, and a median log ratio beyond +-kDecisive
/// (a seam 1.2x worse one way than the other).
constexpr std::size_t kMinScans = 10;
constexpr double kDecisive = 0.18;

/// The plane through a point's neighbours: its unit normal and a point on it, when the
/// neighbours span a surface (not a line along one beam, not a bush).
struct Plane {
  Eigen::Vector3d normal, point;
};
std::optional<Plane> fitPlane(const std::vector<Eigen::Vector3d>& points,
                              std::span<const std::size_t> neighbours) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const std::size_t i : neighbours) mean += points[i];
  mean /= static_cast<double>(neighbours.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const std::size_t i : neighbours) {
    const Eigen::Vector3d d = points[i] - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(neighbours.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d lambda = eigen.eigenvalues();  // ascending
  constexpr double kMinSpread_m = 0.02;                // across the beams: not a line
  if (lambda(1) < kMinSpread_m * kMinSpread_m || lambda(0) > 0.05 * lambda(1)) return std::nullopt;
  return Plane{eigen.eigenvectors().col(0), mean};
}

/// The gyro's rotation over the sweep, as poses (rotation only) every 10 ms from t_start_s, each
/// the previous one turned by the gyro over the step.
Trajectory gyroSweep(const std::vector<calib::GyroReading>& gyro, const io::Scan& scan) {
  Trajectory sweep;
  const double span_s = scan.t_end_s - scan.t_start_s;
  const int steps = std::max(1, static_cast<int>(std::ceil(span_s / 0.01)));
  lie::SO3 R_start_t;
  double t_s = scan.t_start_s;
  sweep.append(t_s, lie::SE3());
  for (int k = 1; k <= steps; ++k) {
    const double t_next_s = scan.t_start_s + span_s * k / steps;
    R_start_t = R_start_t * calib::integrateGyro(gyro, t_s, t_next_s, Eigen::Vector3d::Zero());
    t_s = t_next_s;
    sweep.append(t_s, lie::SE3(R_start_t, Eigen::Vector3d::Zero()));
  }
  return sweep;
}

/// Each point's place in the scan's sweep: 0 at its first firing, 1 at its last.
std::vector<double> sweepFractions(const PointCloud& cloud, const io::Scan& scan) {
  std::vector<double> u(cloud.size());
  const double span_s = scan.t_end_s - scan.t_start_s;
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = (cloud.times_s[i] - scan.t_start_s) / span_s;
  return u;
}

/// The scan's points near its seam (the first and last kWedge of the sweep); the rest are not
/// needed and not kept.
io::Scan seamOnly(const io::Scan& scan) {
  io::Scan seam = scan;
  const std::vector<double> u = sweepFractions(scan.cloud_in_lidar, scan);
  std::vector<std::uint8_t> keep(u.size());
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] = u[i] < kWedge || u[i] > 1.0 - kWedge;
  seam.cloud_in_lidar.keepWhere(keep);
  return seam;
}

/// A scan near its seam with the gyro's turn over its sweep.
struct TurnedSeam {
  io::Scan seam;
  Trajectory turned;
};

struct Recorded {
  std::vector<TurnedSeam> seams;  ///< the scans with made-up times that turned enough
  std::size_t scans = 0;          ///< scans read
  bool times_measured = false;    ///< a scan carried per-point times
  bool imu = false;
};

/// The recording from its start until enough scans turned or the stretch ends.
Recorded readStart(const std::filesystem::path& path, const SystemConfig& config,
                   const SweepCheckOptions& options) {
  io::Recording recording = io::openRecording(path, config.recording, config.rig);
  const Eigen::Matrix3d R_body_imu = config.rig.T_body_imu.rotation().matrix();
  Recorded r;
  std::vector<calib::GyroReading> gyro;
  std::deque<io::Scan> waiting;  // for the gyro to cover their sweep
  std::optional<double> first_scan_s;
  auto judgeWaiting = [&] {
    while (!waiting.empty() && !gyro.empty() && gyro.back().t_s >= waiting.front().t_end_s) {
      const io::Scan& scan = waiting.front();
      if (scan.t_start_s >= gyro.front().t_s) {
        Trajectory turned = gyroSweep(gyro, scan);
        if (turned.back().pose.rotation().angle() >= kMinSweepTurn_rad)
          r.seams.push_back({scan, std::move(turned)});
      }
      waiting.pop_front();
    }
  };
  while (std::optional<io::RecordingEvent> event = recording.next()) {
    if (const auto* imu = std::get_if<ImuSample>(&*event)) {
      r.imu = true;
      gyro.push_back({imu->t_s, R_body_imu * imu->angular_velocity_imu_radps});
      judgeWaiting();
      if (r.seams.size() >= options.enough_scans) break;
      if (first_scan_s && imu->t_s > *first_scan_s + options.max_duration_s) break;
    } else if (const auto* scan = std::get_if<io::Scan>(&*event)) {
      if (!scan->times_invented) {
        r.times_measured = true;
        break;
      }
      if (!first_scan_s) first_scan_s = scan->t_start_s;
      if (scan->t_start_s > *first_scan_s + options.max_duration_s) {
        if (!r.imu) break;  // nothing to wait for
        continue;
      }
      ++r.scans;
      if (scan->t_end_s > scan->t_start_s) waiting.push_back(seamOnly(*scan));
    }
  }
  judgeWaiting();
  return r;
}

}  // namespace

std::optional<double> seamMismatch_m(std::span<const Eigen::Vector3d> positions,
                                     std::span<const double> sweep_fraction,
                                     std::size_t min_pairs) {
  std::vector<Eigen::Vector3d> first;  // the sweep's first firings: the surfaces
  std::vector<std::size_t> last;       // indices of its last firings: the points measured
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (sweep_fraction[i] < kWedge) first.push_back(positions[i]);
    if (sweep_fraction[i] > 1.0 - kWedge) last.push_back(i);
  }
  if (first.size() < min_pairs || last.size() < min_pairs) return std::nullopt;
  const registration::KdTree tree(first);
  // The neighbours span a patch of the surface reaching across a beam or two: the beams lie
  // farther apart with range (5 cm per metre at 32 beams over 90 deg).
  constexpr std::size_t kNeighbours = 12;
  constexpr double kReachPerM = 0.1, kMinReach_m = 0.5;
  std::array<std::size_t, kNeighbours> index{};
  std::array<double, kNeighbours> distance_m2{};
  std::vector<double> residuals_m;
  for (const std::size_t i : last) {
    const std::size_t found = tree.knn(positions[i], kNeighbours, index.data(), distance_m2.data());
    const double reach_m = std::max(kMinReach_m, kReachPerM * positions[i].norm());
    if (found < kNeighbours || distance_m2[found - 1] > reach_m * reach_m) continue;
    if (const std::optional<Plane> plane = fitPlane(tree.points(), index))
      residuals_m.push_back(std::abs(plane->normal.dot(positions[i] - plane->point)));
  }
  if (residuals_m.size() < min_pairs) return std::nullopt;
  return percentile(residuals_m, 50.0);
}

std::string toString(SweepCheck::Verdict verdict) {
  switch (verdict) {
    case SweepCheck::Verdict::kNotNeeded: return "not_needed";
    case SweepCheck::Verdict::kRawSweep: return "raw_sweep";
    case SweepCheck::Verdict::kDeskewedUpstream: return "deskewed_upstream";
    case SweepCheck::Verdict::kUndecided: return "undecided";
  }
  return "?";
}

SweepCheck checkSweeps(const std::filesystem::path& path, const SystemConfig& config,
                       const SweepCheckOptions& options) {
  const Recorded recorded = readStart(path, config, options);
  SweepCheck check;
  check.scans_read = recorded.scans;
  if (recorded.times_measured) {
    check.text = "the scans carry per-point times";
    return check;
  }
  if (recorded.scans == 0 || !recorded.imu) {
    check.verdict = SweepCheck::Verdict::kUndecided;
    check.text = recorded.scans == 0 ? "no scan to judge"
                                     : "no IMU reading to measure the sweeps' turn by";
    return check;
  }
  const ScanPreparation preparation(config.odometry, config.rig);
  std::vector<double> log_ratios;
  for (const auto& [scan, turned] : recorded.seams) {
    const Trajectory still({{scan.t_start_s, lie::SE3()}, {scan.t_end_s, lie::SE3()}});
    const PointCloud as_given = preparation.deskewedInBody(scan, still);
    const PointCloud unturned = preparation.deskewedInBody(scan, turned);
    // The same points in the same order both ways (the deskew keeps the channels).
    const std::vector<double> u = sweepFractions(as_given, scan);
    const std::optional<double> given_m = seamMismatch_m(as_given.positions, u);
    const std::optional<double> unturned_m = seamMismatch_m(unturned.positions, u);
    if (given_m && unturned_m && *given_m > 0.0 && *unturned_m > 0.0)
      log_ratios.push_back(std::log(*given_m / *unturned_m));
  }
  check.scans_used = log_ratios.size();
  if (check.scans_used < kMinScans) {
    check.verdict = SweepCheck::Verdict::kUndecided;
    check.text = fmt::format(
        "undecided: {} of the first {} scans turned enough (>= {:.1f} deg over a sweep) to show "
        "their seam, {} needed (a rig that turns now and then, as a handheld does, shows it)",
        check.scans_used, check.scans_read, kMinSweepTurn_rad * kDegPerRad, kMinScans);
    return check;
  }
  check.median_log_ratio = percentile(log_ratios, 50.0);
  const double ratio = std::exp(check.median_log_ratio);
  check.verdict = check.median_log_ratio < -kDecisive  ? SweepCheck::Verdict::kDeskewedUpstream
                  : check.median_log_ratio > kDecisive ? SweepCheck::Verdict::kRawSweep
                                                       : SweepCheck::Verdict::kUndecided;
  const char* meaning = check.verdict == SweepCheck::Verdict::kDeskewedUpstream
                            ? "deskewed upstream (the seam agrees as given)"
                        : check.verdict == SweepCheck::Verdict::kRawSweep
                            ? "raw sweeps (the seam agrees once the sweep's turn is taken out)"
                            : "undecided";
  check.text = fmt::format(
      "{}: over {} turning scans of the first {} the seam between a sweep's first and last "
      "firings is {:.2f}x as far apart as given as with the gyro's turn taken out",
      meaning, check.scans_used, check.scans_read, ratio);
  return check;
}

std::optional<SweepCheck> resolveDeskewed(const std::filesystem::path& recording,
                                          SystemConfig& config) {
  if (config.recording.deskewed != RecordingConfig::Deskewed::kAuto) return std::nullopt;
  const SweepCheck check = checkSweeps(recording, config);
  switch (check.verdict) {
    case SweepCheck::Verdict::kNotNeeded: break;
    case SweepCheck::Verdict::kDeskewedUpstream:
      config.recording.deskewed = RecordingConfig::Deskewed::kYes;
      logger().warn(
          "{}: clouds without per-point times, {}: every point is taken at the stamp "
          "(recording.deskewed: false deskews them as raw sweeps)",
          recording.string(), check.text);
      break;
    case SweepCheck::Verdict::kRawSweep:
      logger().info("{}: clouds without per-point times, {}: deskewed with times made up from "
                    "the azimuth",
                    recording.string(), check.text);
      break;
    case SweepCheck::Verdict::kUndecided:
      logger().warn(
          "{}: clouds without per-point times, deskewed upstream or not: {}; they are "
          "deskewed with times made up from the azimuth (recording.deskewed: true if they were "
          "deskewed upstream)",
          recording.string(), check.text);
      break;
  }
  return check;
}

}  // namespace taiga::pipeline
