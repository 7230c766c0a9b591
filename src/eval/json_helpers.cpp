#include "json_helpers.hpp"

#include <cmath>

namespace taiga::eval::detail {

using nlohmann::json;

json number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json statisticsJson(const ErrorStatistics& s) {
  if (s.count == 0)  // no values: no statistics
    return {{"count", 0},     {"rmse", nullptr}, {"mean", nullptr}, {"median", nullptr},
            {"std", nullptr}, {"min", nullptr},  {"max", nullptr},  {"sse", nullptr}};
  return {{"count", s.count},           {"rmse", number(s.rmse)}, {"mean", number(s.mean)},
          {"median", number(s.median)}, {"std", number(s.std)},   {"min", number(s.min)},
          {"max", number(s.max)},       {"sse", number(s.sse)}};
}

json vectorJson(const Eigen::Vector3d& v) { return {number(v.x()), number(v.y()), number(v.z())}; }

json timingJson(const TimingStatistics& t, const std::optional<std::string>& file) {
  json stages = json::array();
  for (const StageTiming& s : t.stages)
    stages.push_back({{"name", s.name},
                      {"mean_ms", number(s.mean_ms)},
                      {"median_ms", number(s.median_ms)},
                      {"p95_ms", number(s.p95_ms)},
                      {"max_ms", number(s.max_ms)}});
  json j = {{"scans", t.scan_count},
            {"stages", stages},
            {"scan_period_s", t.scan_period_s},
            {"scans_over_period", t.scans_over_period},
            {"share_over_period", number(t.share_over_period)},
            {"recording_duration_s", number(t.recording_duration_s)},
            {"processing_s", number(t.processing_s)},
            {"real_time_factor", number(t.real_time_factor)}};
  if (file) j["file"] = *file;
  return j;
}

json seriesJson(const std::vector<StampedPose>& poses) {
  json t = json::array(), xyz = json::array(), path = json::array();
  double path_m = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d& p = poses[i].pose.translation();
    if (i > 0) path_m += (p - poses[i - 1].pose.translation()).norm();
    t.push_back(poses[i].t_s);
    xyz.push_back(vectorJson(p));
    path.push_back(path_m);
  }
  return {{"t_s", t}, {"xyz", xyz}, {"path_m", path}};
}

json timingSeriesJson(const TimingTable& table, const TimingStatistics& stats) {
  json stages = json::array();  // in the file's column order, for stacking
  for (std::size_t c = 0; c < table.columns.size(); ++c)
    if (c != table.total_column)
      stages.push_back({{"name", table.columns[c]}, {"ms", table.values_ms[c]}});
  return {{"t_s", table.t_s},
          {"period_ms", stats.scan_period_s * 1000.0},
          {"stages", stages},
          {"total_ms", table.values_ms[table.total_column]}};
}

std::string dump(const json& j) { return j.dump(2) + "\n"; }

}  // namespace taiga::eval::detail
