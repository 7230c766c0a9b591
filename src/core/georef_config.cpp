#include "taiga/core/georef_config.hpp"

#include <array>

namespace taiga {

void GeorefConfig::visit(ConfigVisitor& v) {
  static constexpr std::array<std::string_view, 4> kMethods{"closed", "pf3", "pf6", "robust"};
  v.choice("method", method, kMethods,
           "post-fit of the trajectory to the GNSS fixes: robust (heading and offset from the "
           "horizontal track, tilt from gravity), closed (rigid fit), pf3 (weighted positions), "
           "pf6 (positions and the IMU's absolute orientation)");
  v.field("epsg", epsg, "EPSG code of the projected CRS of the outputs (3067: ETRS-TM35FIN)");
  v.field("max_horizontal_sigma_m", max_horizontal_sigma_m,
          "m, fixes whose reported horizontal 1-sigma is larger are not used (here and by "
          "mapping.gnss_fusion)");
  v.field("max_gap_s", max_gap_s,
          "s, fixes between trajectory poses further apart than this are not used");
  v.field("error_correlation_time_s", error_correlation_time_s,
          "s, correlation time of the GNSS errors (about 30 s under canopy; 0: white noise): the "
          "robust fit's error model starts from it, the other fits and mapping.gnss_fusion "
          "weight by it");
  v.field("p_body_antenna_m", p_body_antenna_m,
          "m, GNSS antenna position in the body frame (here and in mapping.gnss_fusion)");
}

void GeorefConfig::validate() const {
  requireInRange("epsg", epsg, 1024, 999999, "");
  requirePositive("max_horizontal_sigma_m", max_horizontal_sigma_m, "m");
  requirePositive("max_gap_s", max_gap_s, "s");
  requireInRange("error_correlation_time_s", error_correlation_time_s, 0.0, 3600.0, "s");
}

}  // namespace taiga
