#include "run_outputs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <numeric>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/core/percentile.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/trajectory_correction.hpp"

namespace taiga::pipeline {
namespace {

/// Appends a pose to a trajectory unless it is not after the last one (IMU-rate poses repeat the
/// state times at scan boundaries).
void appendIfLater(Trajectory& trajectory, double t_s, const lie::SE3& pose) {
  if (trajectory.empty() || t_s > trajectory.endTime()) trajectory.append(t_s, pose);
}

}  // namespace

std::ofstream openOutput(const std::filesystem::path& path) {
  std::ofstream out(path);
  if (!out) throw InputError(fmt::format("{}: cannot write", path.string()));
  return out;
}

void TrajectoryRecorder::onScan(const ScanOutcome& scan, const lie::SE3& T_map_odom) {
  appendIfLater(online_, scan.t_s, T_map_odom * scan.T_odom_body);
  appendIfLater(odometry_, scan.t_s, scan.T_odom_body);
  for (const StampedPose& p : scan.imu_rate_poses) appendIfLater(imu_rate_, p.t_s, p.pose);
  appendIfLater(imu_rate_, scan.t_s, scan.T_odom_body);
}

void TrajectoryRecorder::onKeyframe(std::uint64_t /*id*/, const ScanOutcome& scan) {
  keyframe_times_s_.push_back(scan.t_s);
}

Trajectory TrajectoryRecorder::write(const std::filesystem::path& dir,
                                     const mapping::PoseGraph& graph,
                                     const lie::SO3& R_level_odom) const {
  const lie::SE3 T_level_odom(R_level_odom, Eigen::Vector3d::Zero());
  Trajectory levelled;
  for (const StampedPose& pose : odometry_.poses())
    levelled.append(pose.t_s, T_level_odom * pose.pose);
  io::writeTum(dir / "trajectory_odometry.tum", levelled);
  io::writeTum(dir / "trajectory_online.tum", online_);
  Trajectory corrected = mapping::correctedTrajectory(odometry_, graph, keyframe_times_s_);
  io::writeTum(dir / "trajectory.tum", corrected);
  io::writeTum(dir / "trajectory_imu.tum",
               mapping::correctedTrajectory(imu_rate_, graph, keyframe_times_s_));
  return corrected;
}

ScanLog::ScanLog(const std::filesystem::path& dir)
    : timing_(openOutput(dir / "timing.csv")), scans_(openOutput(dir / "scans.csv")) {
  timing_ << "t_s,read_ms,deskew_ms,filter_ms,registration_ms,optimization_ms,map_ms,total_ms\n";
  scans_ << "t_s,scan,lidar_factor,fitness_m2,iterations,converged,inliers,hessian_condition,"
            "source_points,keyframe,note,status,health_reason,map_segment,innovation_m,innovation_"
            "deg\n";
}

void ScanLog::chargeReadTime(std::uint64_t scan_index, double read_ms) {
  read_ms_[scan_index] = read_ms;
}

void ScanLog::onScan(const ScanOutcome& scan, const lie::SE3& /*T_map_odom*/) {
  rejected_ += scan.lidar == LidarFactor::kRejected;
  inflated_ += scan.lidar == LidarFactor::kInflated;
  totals_ms_.push_back(scan.timing.total_ms);
  // Scans that gave no outcome (skipped, or held for initialization) leave their read time.
  double read_ms = 0.0;
  if (const auto it = read_ms_.find(scan.scan_index); it != read_ms_.end()) read_ms = it->second;
  read_ms_.erase(read_ms_.begin(), read_ms_.upper_bound(scan.scan_index));
  const ScanTiming& t = scan.timing;
  timing_ << fmt::format("{:.6f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}\n", scan.t_s,
                         read_ms, t.deskew_ms, t.filter_ms, t.registration_ms, t.optimization_ms,
                         t.map_ms, t.total_ms);
  const registration::RegistrationResult& r = scan.registration;
  scans_ << fmt::format(
      "{:.6f},{},{},{:.5f},{},{},{},{:.4g},{},{},\"{}\",{},\"{}\",{},{:.4f},{:.3f}\n", scan.t_s,
      scan.scan_index, lidarFactorName(scan.lidar), r.fitness_m2, r.iterations, r.converged ? 1 : 0,
      r.num_inliers, r.hessian_condition, scan.source_points, scan.keyframe_id ? 1 : 0,
      scan.lidar_note, scanStatusName(scan.health.status), scan.health.reason, scan.map_segment,
      scan.innovation_m, scan.innovation_deg);
}

void ScanLog::onKeyframe(std::uint64_t /*id*/, const ScanOutcome& /*scan*/) { ++keyframes_; }

void ScanLog::fillSummary(RunSummary& s) const {
  s.scans_processed = totals_ms_.size();
  s.imu_samples = imu_samples_;
  s.keyframes = keyframes_;
  s.lidar_rejected = rejected_;
  s.lidar_inflated = inflated_;
  s.local_map_rebuilds = local_map_rebuilds_;
  s.scans_with_made_up_times = made_up_times_;
  if (totals_ms_.empty()) return;
  s.mean_ms = std::accumulate(totals_ms_.begin(), totals_ms_.end(), 0.0) /
              static_cast<double>(totals_ms_.size());
  s.median_ms = percentile(totals_ms_, 50.0);
  s.p95_ms = percentile(totals_ms_, 95.0);
  s.p99_ms = percentile(totals_ms_, 99.0);
  s.max_ms = *std::max_element(totals_ms_.begin(), totals_ms_.end());
}

void writeLoops(const std::filesystem::path& path,
                const std::vector<mapping::LoopRecord>& attempts) {
  std::ofstream out = openOutput(path);
  out << "t_s,keyframe,candidate,distance_m,search_radius_m,fitness_m2,correction_m,correction_"
         "deg,chi2,accepted,note\n";
  for (const mapping::LoopRecord& record : attempts) {
    const mapping::LoopAttempt& a = record.attempt;
    out << fmt::format("{:.6f},{},{},{:.3f},{:.3f},{:.5f},{:.4f},{:.4f},{:.2f},{},\"{}\"\n",
                       record.t_s, a.current, a.candidate.keyframe, a.candidate.distance_m,
                       a.candidate.search_radius_m, a.registration.fitness_m2, a.correction_m,
                       a.correction_deg, record.chi2, a.accepted ? 1 : 0, a.note);
  }
}

void writeClockWindows(const std::filesystem::path& path, const std::vector<ClockWindow>& windows) {
  std::ofstream out = openOutput(path);
  out << "t_s,estimate_s,sigma_s,observable,applied_s,rotation_change_deg,increments,note\n";
  for (const ClockWindow& w : windows)
    out << fmt::format("{:.3f},{:.7f},{:.7f},{},{:.7f},{:.4f},{},\"{}\"\n", w.t_s, w.estimate_s,
                       w.sigma_s, w.observable ? 1 : 0, w.applied_s, w.rotation_change_deg,
                       w.increments, w.failed);
}

}  // namespace taiga::pipeline
