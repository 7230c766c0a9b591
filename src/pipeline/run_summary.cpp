#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "run_outputs.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::pipeline {

// GNSS fused in the mapping graph (mapping.gnss_fusion): what became of the fixes and the
// graph's T_enu_map (docs/mapping.md).
namespace {

nlohmann::ordered_json gnssFusionJson(const mapping::GnssFusionReport& r) {
  nlohmann::ordered_json j = {
      {"fixes", r.total},     {"gated", r.gated}, {"outside_keyframes", r.outside},
      {"waiting", r.waiting}, {"used", r.used},   {"down_weighted", r.down_weighted}};
  if (r.enu_origin)
    j["enu_origin"] = {{"latitude_deg", r.enu_origin->latitude_deg},
                       {"longitude_deg", r.enu_origin->longitude_deg},
                       {"height_ellipsoid_m", r.enu_origin->height_m}};
  if (r.T_enu_map) {
    const Eigen::Matrix4d T = r.T_enu_map->matrix();
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (int i = 0; i < 4; ++i) rows.push_back({T(i, 0), T(i, 1), T(i, 2), T(i, 3)});
    j["T_enu_map"] = rows;
    j["yaw_enu_map_deg"] = r.T_enu_map->rotation().yaw() * kDegPerRad;
  }
  return j;
}

nlohmann::ordered_json finiteOrNull(double value) {
  return std::isfinite(value) ? nlohmann::ordered_json(value) : nlohmann::ordered_json();
}

/// The health monitor's verdict and its stretches; degraded ones only the first few (scans.csv
/// has every scan).
nlohmann::ordered_json sparseJson(const HealthReport& h) {
  nlohmann::ordered_json sparse = nlohmann::ordered_json::array();
  for (const HealthStretch& s : h.sparse)
    sparse.push_back(
        {{"from_s", s.from_s}, {"to_s", s.to_s}, {"scans", s.scans}, {"reason", s.reason}});
  return sparse;
}

nlohmann::ordered_json reattachedJson(const HealthReport& h) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const Reattachment& r : h.reattached)
    out.push_back({{"segment", r.segment},
                   {"t_s", r.t_s},
                   {"correction_m", r.correction_m},
                   {"correction_deg", r.correction_deg},
                   {"overlap", r.overlap}});
  return out;
}

nlohmann::ordered_json healthJson(const HealthReport& h) {
  constexpr std::size_t kListedDegraded = 20;
  nlohmann::ordered_json lost = nlohmann::ordered_json::array();
  nlohmann::ordered_json degraded = nlohmann::ordered_json::array();
  std::size_t degraded_stretches = 0;
  for (const HealthStretch& s : h.stretches) {
    const bool is_lost = s.status == "lost";
    degraded_stretches += !is_lost;
    if (!is_lost && degraded.size() >= kListedDegraded) continue;
    (is_lost ? lost : degraded)
        .push_back(
            {{"from_s", s.from_s}, {"to_s", s.to_s}, {"scans", s.scans}, {"reason", s.reason}});
  }
  return {{"verdict", h.verdict()},
          {"scans_ok", h.ok},
          {"scans_degraded", h.degraded},
          {"scans_lost", h.lost},
          {"map_segments", h.map_segments},
          {"segments_reattached", reattachedJson(h)},
          {"ended_lost", h.ended_lost},
          {"median_innovation_deg", finiteOrNull(h.median_innovation_deg)},
          {"median_innovation_m", finiteOrNull(h.median_innovation_m)},
          {"calibration_suspect", h.calibration_suspect},
          {"sparse_scans", h.sparse_scans},
          {"sparse", sparseJson(h)},
          {"lost", lost},
          {"degraded_stretches", degraded_stretches},
          {"degraded", degraded}};
}

nlohmann::ordered_json calibrationJson(const CalibrationRunReport& c) {
  if (!c.skipped.empty()) return {{"skipped", c.skipped}, {"wall_time_s", c.wall_time_s}};
  const Eigen::Vector3d& sigma = c.rotation_sigma_deg;
  return {{"passes", c.passes},
          {"wall_time_s", c.wall_time_s},
          {"lidar_time_offset_s", c.time_offset_s},
          {"offset_change_s", c.offset_change_s},
          {"offset_sigma_s", c.offset_sigma_s},
          {"offset_observable", c.offset_observable},
          {"rotation_change_deg", c.rotation_change_deg},
          {"rotation_sigma_deg", {sigma.x(), sigma.y(), sigma.z()}},
          {"rotation_observable_axes", c.rotation_observable_axes},
          {"advice", c.advice},
          {"lever_arm",
           {{"change_m", {c.lever_arm_change_m.x(), c.lever_arm_change_m.y(),
                          c.lever_arm_change_m.z()}},
            {"sigma_m", {c.lever_arm_sigma_m.x(), c.lever_arm_sigma_m.y(),
                         c.lever_arm_sigma_m.z()}},
            {"applied_axes", c.lever_arm_applied_axes}}},
          {"gyro_noise",
           {{"verdict", c.gyro_noise_verdict},
            {"measured_radps_sqrthz", c.gyro_noise_measured},
            {"sigma_radps_sqrthz", c.gyro_noise_sigma},
            {"suggested_radps_sqrthz", c.gyro_noise_suggested},
            {"applied", c.gyro_noise_applied},
            {"text", c.gyro_noise_text}}}};
}

nlohmann::ordered_json clockJson(const ClockTrackingReport& c) {
  const auto optional = [](const std::optional<double>& v) -> nlohmann::ordered_json {
    return v ? nlohmann::ordered_json(*v) : nlohmann::ordered_json(nullptr);
  };
  return {{"offset_first_s", c.offset_first_s},
          {"offset_last_s", c.offset_last_s},
          {"windows", c.windows.size()},
          {"held", c.held},
          {"drift_ppm", optional(c.drift_ppm)},
          {"drift_sigma_ppm", optional(c.drift_sigma_ppm)},
          {"text", c.text}};
}

/// null when recording.deskewed was configured (nothing was judged).
nlohmann::ordered_json sweepCheckJson(const std::optional<SweepCheck>& check) {
  if (!check) return nullptr;
  return {{"verdict", toString(check->verdict)},
          {"scans_read", check->scans_read},
          {"scans_used", check->scans_used},
          {"seam_ratio", std::exp(check->median_log_ratio)},
          {"text", check->text}};
}

}  // namespace

void writeSummary(const std::filesystem::path& path, const RunSummary& s,
                  const std::filesystem::path& recording,
                  const std::optional<mapping::GnssFusionReport>& gnss_fusion) {
  nlohmann::ordered_json j = {
      {"recording", recording.string()},
      {"scans", s.scans},
      {"scans_processed", s.scans_processed},
      {"imu_samples", s.imu_samples},
      {"scans_with_made_up_times", s.scans_with_made_up_times},
      {"sweep_check", sweepCheckJson(s.sweep_check)},
      {"keyframes", s.keyframes},
      {"loop_closures", s.loop_closures},
      {"odometry_corrections",
       {{"local_map_rebuilds", s.local_map_rebuilds}, {"wait_s", s.odometry_correction_wait_s}}},
      {"lidar_factors_rejected", s.lidar_rejected},
      {"lidar_factors_inflated", s.lidar_inflated},
      {"map_points", s.map_points},
      {"duration_s", s.duration_s},
      {"path_length_m", s.path_length_m},
      {"time_per_scan_ms",
       {{"mean", s.mean_ms},
        {"p50", s.median_ms},
        {"p95", s.p95_ms},
        {"p99", s.p99_ms},
        {"max", s.max_ms}}},
      {"threads", s.threads},
      {"wall_time_s", s.wall_time_s},
      {"map_export_s", s.map_export_s},
      {"realtime_factor", s.realtime_factor},
      {"peak_memory_mb", s.peak_memory_mb},
      {"initialization", s.initialization},
      {"frame_tilt_deg", {s.frame_tilt_deg.x(), s.frame_tilt_deg.y()}},
      {"health", healthJson(s.health)},
  };
  if (s.trees)
    j["trees_online"] = {{"stems", *s.trees},
                         {"updates", s.trees_updates},
                         {"worker_s", s.trees_work_s},
                         {"final_s", s.trees_final_s}};
  if (s.realtime) {
    j["realtime"] = {{"dropped_scans", s.realtime->dropped_scans},
                     {"latency_ms",
                      {{"p50", s.realtime->latency_p50_ms},
                       {"p95", s.realtime->latency_p95_ms},
                       {"p99", s.realtime->latency_p99_ms},
                       {"max", s.realtime->latency_max_ms}}}};
  }
  if (s.streams)
    j["streams"] = {{"poses_sent", s.streams->poses_sent},
                    {"foxglove_clients", s.streams->foxglove_clients},
                    {"foxglove_messages", s.streams->foxglove_messages},
                    {"foxglove_dropped", s.streams->foxglove_dropped},
                    {"foxglove_history_dropped", s.streams->foxglove_history_dropped}};
  if (s.live) {
    const io::ouster::LiveStats& l = *s.live;
    j["live"] = {{"lidar_packets", l.lidar_packets},
                 {"imu_packets", l.imu_packets},
                 {"other_datagrams", l.other_datagrams},
                 {"kernel_drops", l.kernel_drops},
                 {"bad_packets", l.bad_packets},
                 {"frames", l.frames},
                 {"incomplete_frames", l.incomplete_frames},
                 {"missing_columns", l.missing_columns},
                 {"max_backlog", l.max_backlog},
                 {"stop_reason", l.stop_reason}};
  }
  if (s.georef) {
    const GeorefRunReport& g = *s.georef;
    nlohmann::ordered_json georef = {{"fixes", g.fixes}};
    if (!g.skipped.empty()) {
      georef["skipped"] = g.skipped;
    } else {
      georef.update({{"method", g.method},
                     {"epsg", g.epsg},
                     {"inliers", g.inliers},
                     {"outliers", g.outliers},
                     {"horizontal_rms_m", g.horizontal_rms_m},
                     {"vertical_rms_m", g.vertical_rms_m},
                     {"sigma",
                      {{"east_m", g.sigma[0]},
                       {"north_m", g.sigma[1]},
                       {"up_m", g.sigma[2]},
                       {"roll_deg", g.sigma[3] * kDegPerRad},
                       {"pitch_deg", g.sigma[4] * kDegPerRad},
                       {"yaw_deg", g.sigma[5] * kDegPerRad}}},
                     {"map_export_s", g.map_export_s}});
    }
    j["georef"] = georef;
  }
  if (gnss_fusion) j["gnss_fusion"] = gnssFusionJson(*gnss_fusion);
  if (s.calibration) j["calibration"] = calibrationJson(*s.calibration);
  if (s.clock) j["clock"] = clockJson(*s.clock);
  openOutput(path) << j.dump(2) << "\n";
}

}  // namespace taiga::pipeline
