#pragma once
// JSON building blocks shared by the eval and compare reports. Internal to the eval module.

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "taiga/core/trajectory.hpp"
#include "taiga/eval/statistics.hpp"
#include "taiga/eval/timing.hpp"

namespace taiga::eval::detail {

/// A finite number, or null (JSON has no NaN or infinity).
nlohmann::json number(double value);
nlohmann::json statisticsJson(const ErrorStatistics& s);
nlohmann::json vectorJson(const Eigen::Vector3d& v);
nlohmann::json timingJson(const TimingStatistics& t, const std::optional<std::string>& file);
/// {"t_s": [...], "xyz": [[x, y, z], ...], "path_m": [...]} for plotting.
nlohmann::json seriesJson(const std::vector<StampedPose>& poses);
/// {"t_s", "period_ms", "stages": [{"name", "ms": [...]}], "total_ms"} per scan for plotting.
nlohmann::json timingSeriesJson(const TimingTable& table, const TimingStatistics& stats);
/// Indented by two spaces, ending with a newline.
std::string dump(const nlohmann::json& j);

}  // namespace taiga::eval::detail
