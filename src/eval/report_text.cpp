// Text and Markdown renderings of an evaluation.
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/eval/report.hpp"

namespace taiga::eval {
namespace {

struct StatsRow {
  std::string name;
  ErrorStatistics stats;
};

struct ValueRow {
  std::string name;
  std::string value;
};

std::string deltaText(const RpeOptions& o) {
  if (o.unit == DeltaUnit::kFrames)
    return fmt::format("delta {} frame{}", o.delta, o.delta == 1.0 ? "" : "s");
  return fmt::format("delta {} m", o.delta);
}

std::vector<StatsRow> statsRows(const EvalReport& report) {
  const EvalResult& r = report.result;
  std::vector<StatsRow> rows{{"APE translation (m)", r.ape.translation_m}};
  if (r.ape.rotation_deg) rows.push_back({"APE rotation (deg)", *r.ape.rotation_deg});
  const auto add_rpe = [&](const RpeResult& rpe) {
    const std::string d = deltaText(rpe.options);
    rows.push_back({fmt::format("RPE translation (m), {}", d), rpe.translation_m});
    if (report.options.rotation)
      rows.push_back({fmt::format("RPE rotation (deg), {}", d), rpe.rotation_deg});
  };
  add_rpe(r.rpe_frames);
  if (r.rpe_metres) add_rpe(*r.rpe_metres);
  return rows;
}

std::string transformText(const EvalResult& r) {
  const Eigen::Vector3d& t = r.transform.T_ref_est.translation();
  return fmt::format("rotation {:.6f} deg, translation [{:.6f}, {:.6f}, {:.6f}] m, scale {:.6f}",
                     r.transform.T_ref_est.rotation().angle() * kDegPerRad, t.x(), t.y(), t.z(),
                     r.transform.scale);
}

std::vector<ValueRow> valueRows(const EvalReport& report) {
  const EvalResult& r = report.result;
  std::vector<ValueRow> rows;
  const Eigen::Vector3d& axis = r.ape.rmse_per_axis_m;
  rows.push_back({"APE translation RMSE per axis (m)",
                  fmt::format("x {:.6f}  y {:.6f}  z {:.6f}", axis.x(), axis.y(), axis.z())});
  if (r.kitti) {
    rows.push_back({"KITTI translational error (%)",
                    fmt::format("{:.4f} ({} segments of 100..800 m)",
                                r.kitti->translation_error_percent, r.kitti->segments.size())});
    rows.push_back({"KITTI rotational error (deg/100 m)",
                    fmt::format("{:.4f}", r.kitti->rotation_error_deg_per_100m)});
  } else {
    rows.push_back({"KITTI errors", "none: the reference path is not longer than 100 m"});
  }
  rows.push_back({"End-point drift (m)",
                  fmt::format("{:.6f} (dx {:.6f}, dy {:.6f}, dz {:.6f}; first poses aligned)",
                              r.drift.drift_m, r.drift.drift_vector_m.x(),
                              r.drift.drift_vector_m.y(), r.drift.drift_vector_m.z())});
  rows.push_back({"End-point drift (% of path)",
                  fmt::format("{:.4f} (reference path {:.3f} m)", r.drift.drift_percent,
                              r.drift.reference_path_length_m)});
  rows.push_back({"Path length ratio (est / ref)",
                  fmt::format("{:.6f} (over steps of at least {:.0f} m of the reference)",
                              r.drift.path_length_ratio, DriftResult::kPathStep_m)});
  const Eigen::Vector3d& heading = r.drift.heading_aligned_drift_vector_m;
  rows.push_back({"End-point drift, heading aligned (m)",
                  fmt::format("dx {:.6f}, dy {:.6f}, dz {:.6f}; first poses aligned in position "
                              "and heading, not in roll and pitch",
                              heading.x(), heading.y(), heading.z())});
  if (report.show_distance) {
    const DistanceDistribution& d = r.distance;
    rows.push_back({"Distance est-ref, unaligned (m)",
                    fmt::format("mean {:.6f}  std {:.6f}  min {:.6f}  max {:.6f}", d.mean_m,
                                d.std_m, d.min_m, d.max_m)});
    for (std::size_t k = 0; k < d.counts.size(); ++k) {
      const double lo = d.first_bin_start_m + static_cast<double>(k) * d.bin_width_m;
      rows.push_back({fmt::format("  [{:.2f}, {:.2f}) m", lo, lo + d.bin_width_m),
                      fmt::format("{}", d.counts[k])});
    }
  }
  if (report.map_sharpness) {
    const MapSharpness& m = *report.map_sharpness;
    rows.push_back({"Map sharpness RMS (m)",
                    fmt::format("{:.6f} ({} of {} points of {}, distances capped at {} m)", m.rms_m,
                                m.points_scored, m.map_points, report.map_file, m.cap_m)});
    rows.push_back(
        {"Map distance to true surfaces (m)",
         fmt::format("mean {:.6f}  median {:.6f}  p95 {:.6f}  beyond {} m: {:.3f} %", m.mean_m,
                     m.median_m, m.p95_m, m.cap_m, 100.0 * m.fraction_beyond_cap)});
  }
  if (report.trees) {
    const TreeAccuracy& t = *report.trees;
    rows.push_back(
        {"Trees (detected / reference)",
         fmt::format("{} / {} (DBH >= {} cm, within {} m of the path; {} against {})", t.detected,
                     t.reference, 100 * t.options.min_dbh_m, t.options.max_path_distance_m,
                     report.trees_file, report.ref_trees_file)});
    rows.push_back({"Tree detection rate (%)", fmt::format("{:.1f}", 100 * t.recall)});
    rows.push_back(
        {"Tree commission (%)", fmt::format("{:.1f} ({} of {} stems match no tree)",
                                            100 * t.commission, t.false_stems, t.estimated)});
    rows.push_back({"DBH error (cm)", fmt::format("rmse {:.2f}  bias {:+.2f}", 100 * t.dbh_rmse_m,
                                                  100 * t.dbh_bias_m)});
    if (!std::isnan(t.dbh_within_2_sigma))
      rows.push_back({"DBH error within 2 sigma (%)",
                      fmt::format("{:.1f} (about 95 if the stated sigma is honest)",
                                  100 * t.dbh_within_2_sigma)});
    rows.push_back({"Stem position RMSE (cm)", fmt::format("{:.2f}", 100 * t.position_rmse_m)});
    rows.push_back({"Tree height error (m)",
                    fmt::format("rmse {:.2f}  bias {:+.2f}", t.height_rmse_m, t.height_bias_m)});
    rows.push_back({"Overlapping-tree ratio (%)", fmt::format("{:.1f}", 100 * t.overlap_ratio)});
    for (const std::vector<TreeClass>* classes : {&t.by_dbh, &t.by_distance})
      for (const TreeClass& c : *classes)
        rows.push_back({fmt::format("  detected, {}", c.label),
                        fmt::format("{} of {}", c.detected, c.reference)});
  }
  if (report.ape_by_status) {
    for (const StatusApe& s : *report.ape_by_status)
      rows.push_back({fmt::format("APE of {} scans (m)", s.status),
                      fmt::format("rmse {:.6f}  max {:.6f}  ({} poses, {})", s.rmse_m, s.max_m,
                                  s.poses, report.scans_file)});
    if (const std::optional<StatusApe>& ok = report.ok_self_aligned)
      rows.push_back(
          {"APE of ok scans, aligned alone (m)",
           fmt::format("rmse {:.6f}  max {:.6f}  ({} poses)", ok->rmse_m, ok->max_m, ok->poses)});
  }
  if (report.timing) {
    const TimingStatistics& t = *report.timing;
    for (const StageTiming& s : t.stages)
      rows.push_back({fmt::format("Time {} (ms)", s.name),
                      fmt::format("mean {:.3f}  median {:.3f}  p95 {:.3f}  max {:.3f}", s.mean_ms,
                                  s.median_ms, s.p95_ms, s.max_ms)});
    rows.push_back({fmt::format("Scans over the {} ms period", t.scan_period_s * 1000.0),
                    fmt::format("{} of {} ({:.2f} %)", t.scans_over_period, t.scan_count,
                                t.share_over_period * 100.0)});
    rows.push_back({"Real-time factor",
                    fmt::format("{:.3f} ({:.3f} s of data in {:.3f} s)", t.real_time_factor,
                                t.recording_duration_s, t.processing_s)});
  }
  return rows;
}

std::string headerText(const EvalReport& report) {
  const EvalResult& r = report.result;
  std::string out;
  out += fmt::format("estimate    {} ({} poses)\n", report.est_file, r.est_count);
  out += fmt::format("reference   {} ({} poses)\n", report.ref_file, r.ref_count);
  out += fmt::format("associated  {} pairs (|dt| <= {} s, estimate time offset {} s)\n",
                     r.pairs.size(), report.options.association.t_max_diff_s,
                     report.options.association.t_offset_s);
  out += fmt::format("alignment   {}: {}\n", alignmentName(r.alignment), transformText(r));
  if (report.timing_file)
    out += fmt::format("timing      {} ({} scans)\n", *report.timing_file,
                       report.timing ? report.timing->scan_count : 0);
  return out;
}

}  // namespace

std::string formatEvalText(const EvalReport& report) {
  std::string out = headerText(report) + "\n";
  out += fmt::format("{:<40} {:>8} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12}\n", "", "count",
                     "rmse", "mean", "median", "std", "min", "max");
  for (const StatsRow& row : statsRows(report)) {
    const ErrorStatistics& s = row.stats;
    if (s.count == 0) {
      out += fmt::format("{:<40} {:>8} (no pairs: the trajectory is shorter than the delta)\n",
                         row.name, 0);
      continue;
    }
    out += fmt::format("{:<40} {:>8} {:>12.6f} {:>12.6f} {:>12.6f} {:>12.6f} {:>12.6f} {:>12.6f}\n",
                       row.name, s.count, s.rmse, s.mean, s.median, s.std, s.min, s.max);
  }
  out += "\n";
  for (const ValueRow& row : valueRows(report))
    out += fmt::format("{:<40} {}\n", row.name, row.value);
  return out;
}

std::string formatEvalMarkdown(const EvalReport& report) {
  std::string out;
  const EvalResult& r = report.result;
  out += fmt::format(
      "Estimate `{}` ({} poses) against reference `{}` ({} poses): {} associated "
      "pairs, alignment {} ({}).\n\n",
      report.est_file, r.est_count, report.ref_file, r.ref_count, r.pairs.size(),
      alignmentName(r.alignment), transformText(r));
  out += "| metric | count | rmse | mean | median | std | min | max |\n";
  out += "|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const StatsRow& row : statsRows(report)) {
    const ErrorStatistics& s = row.stats;
    if (s.count == 0) {
      out += fmt::format("| {} | 0 | - | - | - | - | - | - |\n", row.name);
      continue;
    }
    out += fmt::format("| {} | {} | {:.6f} | {:.6f} | {:.6f} | {:.6f} | {:.6f} | {:.6f} |\n",
                       row.name, s.count, s.rmse, s.mean, s.median, s.std, s.min, s.max);
  }
  out += "\n| metric | value |\n|---|---|\n";
  for (const ValueRow& row : valueRows(report))
    out += fmt::format("| {} | {} |\n", row.name, row.value);
  return out;
}

}  // namespace taiga::eval
