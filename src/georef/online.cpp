#include "taiga/georef/online.hpp"

#include <algorithm>

#include "taiga/core/errors.hpp"

namespace taiga::georef {

OnlineGeoreferencer::OnlineGeoreferencer(const GeorefSettings& settings)
    : settings_(settings), converter_(settings.epsg) {}

void OnlineGeoreferencer::addPose(double t_s, const lie::SE3& T_world_body) {
  if (!published_.empty() && t_s <= published_.endTime()) return;
  published_.append(t_s, T_world_body);
  associatePending();
}

void OnlineGeoreferencer::addFix(const GnssFix& fix) {
  const PreparedFixes prepared = prepareFixes({fix}, settings_.gating, converter_, origin_);
  if (prepared.fixes.empty()) {
    ++gated_;
    return;
  }
  if (!origin_) origin_ = prepared.origin;
  pending_.push_back(prepared.fixes.front());
  associatePending();
}

void OnlineGeoreferencer::associatePending() {
  if (published_.empty()) return;
  // Fixes up to the newest published pose are settled; later ones wait.
  const auto settled = std::stable_partition(pending_.begin(), pending_.end(), [&](const LocalFix& f) {
    return f.t_s <= published_.endTime();
  });
  if (settled == pending_.begin()) return;
  const std::vector<LocalFix> ready(pending_.begin(), settled);
  pending_.erase(pending_.begin(), settled);
  const Association association = associateFixes(published_, ready, settings_.association);
  if (association.pairs.empty()) return;
  associated_.insert(associated_.end(), association.pairs.begin(), association.pairs.end());
  // The error model is chosen again whenever the fixes have grown by a quarter since the last
  // choice (a choice tries about ninety models; an hour of 1 Hz fixes refitted with all of them
  // at every fix would cost minutes), and kept in between.
  FitOptions options = settings_.fit;
  const bool choose = !model_ || 4 * associated_.size() >= 5 * model_fixes_;
  if (!choose) options.error_model = model_;
  try {
    estimate_ = OnlineEstimate{.t_s = associated_.back().fix.t_s,
                               .fixes = associated_.size(),
                               .fit = fitRobust(associated_, options)};
    if (choose) {
      model_ = estimate_->fit.error_model;
      model_fixes_ = associated_.size();
    }
  } catch (const InputError&) {
    // Too few fixes, or too little motion for the heading yet: keep the previous estimate.
  }
}

std::optional<GridPose> OnlineGeoreferencer::toGrid(double t_s,
                                                    const lie::SE3& T_world_body) const {
  if (!estimate_) return std::nullopt;
  Trajectory one;
  one.append(t_s, T_world_body);
  return trajectoryInGrid(one, estimate_->fit.T_enu_world, *origin_, converter_).front();
}

}  // namespace taiga::georef
