#pragma once
// Online georeferencing (issue 9 item 4): an estimator beside the odometry that keeps the
// world-to-grid transform up to date while a run goes on, so that poses can be published in the
// national grid live. It never touches the map graph (the thesis found that fusing poor GNSS
// could break the map): it only watches the odometry's published poses and the fixes.
//
// A fix is associated once the odometry has published poses past its time (the published poses
// do not change afterwards); each associated fix refits the `robust` method (fit.hpp) over all
// fixes so far, with the error model it chose last (chosen again when the fixes have grown by a
// quarter). Until the walk spans enough ground for the heading (fitRobust's own test) there is
// no estimate.

#include <optional>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/geo/coordinates.hpp"
#include "taiga/georef/association.hpp"
#include "taiga/georef/fit.hpp"
#include "taiga/georef/georeference.hpp"
#include "taiga/georef/grid_output.hpp"

namespace taiga::georef {

struct OnlineEstimate {
  double t_s = 0.0;          ///< time of the newest fix it uses
  std::size_t fixes = 0;     ///< fixes it uses
  GeorefFit fit;             ///< T_enu_world and its uncertainty
};

class OnlineGeoreferencer {
 public:
  /// Uses settings.epsg, gating, association and fit options; the method is always robust.
  explicit OnlineGeoreferencer(const GeorefSettings& settings);

  /// A pose as the odometry published it (times increasing).
  void addPose(double t_s, const lie::SE3& T_world_body);
  /// A fix (any time order relative to the poses); gated fixes are counted and dropped.
  void addFix(const GnssFix& fix);

  const std::optional<OnlineEstimate>& estimate() const { return estimate_; }
  /// The pose in the grid with the current estimate; nothing before the first estimate.
  std::optional<GridPose> toGrid(double t_s, const lie::SE3& T_world_body) const;
  std::size_t fixesGated() const { return gated_; }

 private:
  void associatePending();

  GeorefSettings settings_;
  geo::CoordinateConverter converter_;
  std::optional<geo::Geodetic> origin_;  ///< ENU origin: the first fix that passes the gate
  Trajectory published_;
  std::vector<LocalFix> pending_;  ///< not yet covered by published poses
  std::vector<AssociatedFix> associated_;
  std::optional<OnlineEstimate> estimate_;
  std::optional<GnssErrorModel> model_;  ///< the robust fit's error model, last chosen at
  std::size_t model_fixes_ = 0;          ///< this many associated fixes
  std::size_t gated_ = 0;
};

}  // namespace taiga::georef
