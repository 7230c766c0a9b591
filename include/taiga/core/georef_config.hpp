#pragma once
// Configuration of the georeferencing at the end of taiga run and in taiga georef (issue 9,
// thesis 3.4; docs/georeferencing.md), and of the GNSS receiver for mapping.gnss_fusion too:
// one gate, one error correlation time, one lever arm.

#include <Eigen/Core>
#include <string>

#include "taiga/core/config.hpp"

namespace taiga {

struct GeorefConfig final : ConfigSection {
  /// Post-fit method: closed, pf3, pf6 or robust (the thesis' recommendation).
  std::string method = "robust";
  int epsg = 3067;  ///< projected CRS of the outputs (ETRS-TM35FIN)
  double max_horizontal_sigma_m = 5.0;  ///< fixes reporting a worse horizontal 1-sigma are gated
  double max_gap_s = 1.0;  ///< fixes between trajectory poses further apart are not used
  /// Correlation time of the GNSS errors under canopy; widens the reported uncertainty.
  double error_correlation_time_s = 30.0;
  Eigen::Vector3d p_body_antenna_m = Eigen::Vector3d::Zero();  ///< antenna lever arm

  void visit(ConfigVisitor& v) override;
  void validate() const override;
};

}  // namespace taiga
