#include "taiga/mapping/gnss_fusion.hpp"

#include <algorithm>
#include <cmath>

#include "taiga/core/errors.hpp"
#include "taiga/core/log.hpp"
#include "taiga/georef/fit.hpp"

namespace taiga::mapping {
namespace {

// Variance of a long mean of first-order Gauss-Markov samples dt apart relative to white noise:
// sum over all lags k of rho^|k| = (1 + rho) / (1 - rho), rho = exp(-dt / tau).
double correlationFactor(double dt_s, double tau_s) {
  if (tau_s <= 0.0) return 1.0;
  const double rho = std::exp(-std::max(dt_s, 1e-3) / tau_s);
  return (1.0 + rho) / (1.0 - rho);
}

}  // namespace

GnssFusion::GnssFusion(const MappingConfig& config, const GeorefConfig& gnss)
    : config_(config),
      correlation_time_s_(gnss.error_correlation_time_s),
      p_body_antenna_m_(gnss.p_body_antenna_m),
      gating_{.max_horizontal_sigma_m = gnss.max_horizontal_sigma_m},
      converter_(3067) {}  // only its ENU conversion (through ECEF) is used, any EPSG code does

void GnssFusion::addFix(const GnssFix& fix) {
  ++counts_.total;
  const georef::PreparedFixes prepared = georef::prepareFixes({fix}, gating_, converter_, origin_);
  counts_.gated += prepared.gated();
  if (prepared.fixes.empty()) return;
  if (!origin_) origin_ = prepared.origin;
  const georef::LocalFix& local = prepared.fixes.front();
  const auto later =
      std::upper_bound(queued_.begin(), queued_.end(), local.t_s,
                       [](double t_s, const georef::LocalFix& queued) { return t_s < queued.t_s; });
  queued_.insert(later, local);
}

void GnssFusion::attach(const georef::LocalFix& fix, const PoseGraph& graph,
                        const std::vector<double>& keyframe_times_s) {
  // The bracketing keyframes a < b with t_a <= t_fix <= t_b.
  const auto after = std::lower_bound(keyframe_times_s.begin(), keyframe_times_s.end(), fix.t_s);
  const auto b = static_cast<std::size_t>(after - keyframe_times_s.begin());
  const std::size_t a = b == 0 ? 0 : b - 1;
  const double span_s = keyframe_times_s[b] - keyframe_times_s[a];
  const double s = span_s > 0.0 ? (fix.t_s - keyframe_times_s[a]) / span_s : 0.0;
  const lie::SE3 T_odom_fix = lie::interpolate(graph.odometryPose(a), graph.odometryPose(b), s);
  const std::size_t nearest = s <= 0.5 ? a : b;
  // The antenna in the nearest keyframe's body frame.
  const Eigen::Vector3d d_body =
      graph.odometryPose(nearest).inverse() * T_odom_fix * p_body_antenna_m_;

  const double dt_s =
      previous_fix_t_s_ ? std::abs(fix.t_s - *previous_fix_t_s_) : correlation_time_s_;
  previous_fix_t_s_ = fix.t_s;
  Attached attached{
      .observation = {.keyframe = nearest,
                      .d_body = d_body,
                      .p_enu = fix.p_enu,
                      .covariance_enu_m2 = fix.covariance_enu_m2,
                      .huber_sigmas = config_.gnss_huber_sigmas,
                      .weight = 1.0 / correlationFactor(dt_s, correlation_time_s_)},
      .t_s = fix.t_s};
  attached_.push_back(attached);
}

bool GnssFusion::afterKeyframe(PoseGraph& graph, const std::vector<double>& keyframe_times_s) {
  if (keyframe_times_s.empty()) return false;
  const double t_last_s = keyframe_times_s.back();
  // Queued fixes before the first keyframe can never be attached.
  auto ready = queued_.begin();
  for (; ready != queued_.end() && ready->t_s <= t_last_s; ++ready) {
    if (ready->t_s < keyframe_times_s.front())
      ++counts_.outside;
    else
      attach(*ready, graph, keyframe_times_s);
  }
  queued_.erase(queued_.begin(), ready);

  if (!started_) tryStart(graph);
  if (started_) {
    for (const Attached& attached : attached_) graph.addGnss(attached.observation);
    counts_.used += attached_.size();
    attached_.clear();
  }
  if (!graph.hasUnsolvedFactors()) return false;
  if (last_solve_t_s_ && t_last_s - *last_solve_t_s_ < config_.gnss_optimize_interval_s)
    return false;
  last_solve_t_s_ = t_last_s;
  return true;
}

void GnssFusion::tryStart(PoseGraph& graph) {
  if (attached_.size() < static_cast<std::size_t>(config_.gnss_min_fixes)) return;
  // Antenna positions at the current poses (loop closures may have moved the keyframes since the
  // fixes were attached).
  std::vector<georef::AssociatedFix> pairs;
  for (const Attached& attached : attached_) {
    const GnssObservation& o = attached.observation;
    pairs.push_back(
        {.fix = {.t_s = attached.t_s, .p_enu = o.p_enu, .covariance_enu_m2 = o.covariance_enu_m2},
         .T_world_body = graph.pose(o.keyframe),
         .p_world = graph.pose(o.keyframe) * o.d_body});
  }
  double spread_m = 0.0;
  for (const georef::AssociatedFix& pair : pairs)
    spread_m = std::max(spread_m, (pair.p_world - pairs.front().p_world).head<2>().norm());
  if (spread_m < config_.gnss_min_spread_m) return;

  georef::FitOptions options;
  options.error_correlation_time_s = correlation_time_s_;
  try {
    const georef::GeorefFit fit = georef::fitRobust(pairs, options);
    graph.setEnuMap(fit.T_enu_world);
    started_ = true;
    logger().debug("GNSS fusion starts with {} fixes over {:.1f} m", pairs.size(), spread_m);
  } catch (const InputError& error) {
    // Degenerate geometry (e.g. the fixes barely move sideways): wait for more fixes.
    logger().debug("GNSS fusion waits: {}", error.what());
  }
}

bool GnssFusion::finish(const PoseGraph& graph) {
  counts_.outside += queued_.size();
  queued_.clear();
  return graph.hasUnsolvedFactors();
}

GnssFusionReport GnssFusion::report(const PoseGraph& graph) const {
  GnssFusionReport report = counts_;
  report.waiting = attached_.size();
  report.enu_origin = origin_;
  report.T_enu_map = graph.enuMap();
  const std::vector<double> whitened = graph.gnssWhitenedResiduals();
  report.down_weighted =
      static_cast<std::size_t>(std::count_if(whitened.begin(), whitened.end(), [&](double norm) {
        return norm > config_.gnss_huber_sigmas;
      }));
  return report;
}

}  // namespace taiga::mapping
