// JSON renderings of an evaluation: the report for scripts and the series for the plots.
#include <cmath>
#include <nlohmann/json.hpp>

#include "json_helpers.hpp"
#include "taiga/eval/report.hpp"

namespace taiga::eval {
namespace {

using nlohmann::json;

json rpeJson(const RpeResult& rpe) {
  return {{"delta", rpe.options.delta},
          {"delta_unit", rpe.options.unit == DeltaUnit::kFrames ? "frames" : "m"},
          {"pairs", rpe.pairs.size()},
          {"translation_m", detail::statisticsJson(rpe.translation_m)},
          {"rotation_deg", detail::statisticsJson(rpe.rotation_deg)}};
}

// The tree list's scores, every match, missed tree and false stem (`--trees`); the JSON report
// and the plot data (scripts/plot_eval.py's tree map) both carry it.
json treesJson(const EvalReport& report) {
  const TreeAccuracy& t = *report.trees;
  auto classes = [](const std::vector<TreeClass>& list) {
    json out = json::array();
    for (const TreeClass& c : list)
      out.push_back({{"label", c.label}, {"reference", c.reference}, {"detected", c.detected}});
    return out;
  };
  auto points = [](const std::vector<Eigen::Vector2d>& list) {
    json out = json::array();
    for (const Eigen::Vector2d& p : list) out.push_back({p.x(), p.y()});
    return out;
  };
  json matches = json::array();
  for (const TreeMatch& m : t.matches)
    matches.push_back({{"est_id", m.est_id},
                       {"ref_id", m.ref_id},
                       {"est_dbh_m", m.est_dbh_m},
                       {"ref_dbh_m", m.ref_dbh_m},
                       {"est_xy_m", {m.est_xy_m.x(), m.est_xy_m.y()}},
                       {"ref_xy_m", {m.ref_xy_m.x(), m.ref_xy_m.y()}},
                       {"position_error_m", (m.est_xy_m - m.ref_xy_m).norm()},
                       {"path_distance_m", m.path_distance_m}});
  return {{"trees", report.trees_file},
          {"ref_trees", report.ref_trees_file},
          {"match_m", t.options.match_m},
          {"min_dbh_m", t.options.min_dbh_m},
          {"max_path_distance_m", t.options.max_path_distance_m},
          {"reference", t.reference},
          {"detected", t.detected},
          {"estimated", t.estimated},
          {"false_stems", t.false_stems},
          {"recall", t.recall},
          {"commission", t.commission},
          {"dbh_rmse_m", t.dbh_rmse_m},
          {"dbh_bias_m", t.dbh_bias_m},
          {"dbh_within_2_sigma", t.dbh_within_2_sigma},
          {"position_rmse_m", t.position_rmse_m},
          {"height_rmse_m", t.height_rmse_m},
          {"height_bias_m", t.height_bias_m},
          {"overlap_ratio", t.overlap_ratio},
          {"by_dbh", classes(t.by_dbh)},
          {"by_distance", classes(t.by_distance)},
          {"missed_ref_ids", t.missed_ids},
          {"false_est_ids", t.false_ids},
          {"missed_xy_m", points(t.missed_xy_m)},
          {"false_xy_m", points(t.false_xy_m)},
          {"matches", std::move(matches)}};
}

}  // namespace

std::string formatEvalJson(const EvalReport& report) {
  const EvalResult& r = report.result;
  json j;
  j["estimate"] = {{"file", report.est_file}, {"poses", r.est_count}};
  j["reference"] = {{"file", report.ref_file}, {"poses", r.ref_count}};
  j["association"] = {{"pairs", r.pairs.size()},
                      {"t_max_diff_s", report.options.association.t_max_diff_s},
                      {"t_offset_s", report.options.association.t_offset_s}};
  const Eigen::Quaterniond q = r.transform.T_ref_est.rotation().quaternion();
  j["alignment"] = {{"method", std::string(alignmentName(r.alignment))},
                    {"translation_m", detail::vectorJson(r.transform.T_ref_est.translation())},
                    {"quaternion_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                    {"scale", r.transform.scale}};
  json ape = {{"translation_m", detail::statisticsJson(r.ape.translation_m)},
              {"rmse_per_axis_m", detail::vectorJson(r.ape.rmse_per_axis_m)}};
  if (r.ape.rotation_deg) ape["rotation_deg"] = detail::statisticsJson(*r.ape.rotation_deg);
  j["ape"] = ape;
  j["rpe"] = json::array({rpeJson(r.rpe_frames)});
  if (r.rpe_metres) j["rpe"].push_back(rpeJson(*r.rpe_metres));
  if (r.kitti)
    j["kitti"] = {{"segments", r.kitti->segments.size()},
                  {"translation_error_percent", r.kitti->translation_error_percent},
                  {"rotation_error_deg_per_100m", r.kitti->rotation_error_deg_per_100m}};
  else
    j["kitti"] = nullptr;
  j["drift"] = {{"drift_m", r.drift.drift_m},
                {"drift_vector_m", detail::vectorJson(r.drift.drift_vector_m)},
                {"reference_path_length_m", r.drift.reference_path_length_m},
                {"drift_percent", r.drift.drift_percent},
                {"path_length_ratio", r.drift.path_length_ratio},
                {"heading_aligned_drift_vector_m",
                 detail::vectorJson(r.drift.heading_aligned_drift_vector_m)}};
  const DistanceDistribution& d = r.distance;
  j["distance"] = {{"mean_m", d.mean_m},
                   {"std_m", d.std_m},
                   {"min_m", d.min_m},
                   {"max_m", d.max_m},
                   {"bin_width_m", d.bin_width_m},
                   {"first_bin_start_m", d.first_bin_start_m},
                   {"counts", d.counts}};
  if (report.timing) j["timing"] = detail::timingJson(*report.timing, report.timing_file);
  if (report.ape_by_status) {
    json by_status = json::object();
    for (const StatusApe& s : *report.ape_by_status)
      by_status[s.status] = {{"poses", s.poses}, {"rmse_m", s.rmse_m}, {"max_m", s.max_m}};
    j["ape_by_status"] = {{"scans", report.scans_file}, {"statuses", by_status}};
    if (const std::optional<StatusApe>& ok = report.ok_self_aligned)
      j["ape_by_status"]["ok_aligned_alone"] = {
          {"poses", ok->poses}, {"rmse_m", ok->rmse_m}, {"max_m", ok->max_m}};
  }
  if (report.map_sharpness) {
    const MapSharpness& m = *report.map_sharpness;
    j["map_sharpness"] = {
        {"map", report.map_file},     {"scene", report.scene_dir},
        {"map_points", m.map_points}, {"points_scored", m.points_scored},
        {"cap_m", m.cap_m},           {"rms_m", m.rms_m},
        {"mean_m", m.mean_m},         {"median_m", m.median_m},
        {"p95_m", m.p95_m},           {"fraction_beyond_cap", m.fraction_beyond_cap}};
  }
  if (report.trees) j["trees"] = treesJson(report);
  return detail::dump(j);
}

std::string formatEvalPlotData(const EvalReport& report) {
  const EvalResult& r = report.result;
  json j;
  j["kind"] = "eval";
  j["est_label"] = report.est_file;
  j["ref_label"] = report.ref_file;
  j["alignment"] = std::string(alignmentName(r.alignment));
  j["reference"] = detail::seriesJson(r.pairs.ref);
  j["estimate"] = detail::seriesJson(r.est_aligned);
  j["ape_m"] = r.ape.translation_error_m;
  if (report.timing_table && report.timing)
    j["timing"] = detail::timingSeriesJson(*report.timing_table, *report.timing);
  if (report.trees) j["trees"] = treesJson(report);  // for the tree map, trees.png
  return detail::dump(j);
}

}  // namespace taiga::eval
