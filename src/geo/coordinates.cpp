#include "taiga/geo/coordinates.hpp"

#include <fmt/format.h>
#include <proj.h>

#include <cmath>

#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::geo {
namespace {

std::string projError(PJ_CONTEXT* context) {
  return proj_context_errno_string(context, proj_context_errno(context));
}

/// An operation in traditional GIS order (longitude, latitude in degrees; easting, northing),
/// whatever axis order the EPSG definitions use.
PJ* normalized(PJ_CONTEXT* context, PJ* operation) {
  PJ* result = proj_normalize_for_visualization(context, operation);
  proj_destroy(operation);
  return result;
}

PJ_COORD apply(PJ* operation, PJ_DIRECTION direction, double a, double b, double c,
               const char* what) {
  proj_errno_reset(operation);
  const PJ_COORD out = proj_trans(operation, direction, proj_coord(a, b, c, 0.0));
  if (proj_errno(operation) != 0 || !std::isfinite(out.xyz.x) || !std::isfinite(out.xyz.y) ||
      !std::isfinite(out.xyz.z)) {
    throw InputError(fmt::format("{} ({}, {}, {}): outside the domain of the conversion ({})",
                                 what, a, b, c, proj_context_errno_string(nullptr, proj_errno(operation))));
  }
  return out;
}
}  // namespace

struct CoordinateConverter::Proj {
  PJ_CONTEXT* context = nullptr;
  PJ* geodetic_to_projected = nullptr;
  PJ* geodetic_to_ecef = nullptr;
  ~Proj() {
    proj_destroy(geodetic_to_ecef);
    proj_destroy(geodetic_to_projected);
    proj_context_destroy(context);
  }
};

CoordinateConverter::CoordinateConverter(int epsg) : epsg_(epsg), proj_(std::make_unique<Proj>()) {
  PJ_CONTEXT* context = proj_->context = proj_context_create();
  proj_log_level(context, PJ_LOG_NONE);  // failures become exceptions with PROJ's reason
  const std::string code = fmt::format("EPSG:{}", epsg);
  PJ* crs = proj_create(context, code.c_str());
  if (crs == nullptr) {
    throw InputError(fmt::format("{}: unknown CRS code ({})", code, projError(context)));
  }
  if (proj_get_type(crs) != PJ_TYPE_PROJECTED_CRS) {
    const std::string found = proj_get_name(crs) ? proj_get_name(crs) : "?";
    proj_destroy(crs);
    throw InputError(fmt::format(
        "{}: '{}' is not a projected CRS; expected a map grid such as EPSG:3067 (ETRS-TM35FIN) or "
        "EPSG:32635 (WGS 84 / UTM zone 35N)",
        code, found));
  }
  name_ = proj_get_name(crs) ? proj_get_name(crs) : code;
  // WKT1 as GDAL writes it: what LAS 1.4 readers (PDAL, LAStools, CloudCompare) expect.
  const char* wkt = proj_as_wkt(context, crs, PJ_WKT1_GDAL, nullptr);
  wkt_ = wkt ? wkt : "";
  // From the CRS's own geodetic base (ETRS89 for 3067): a pure conversion, no datum shift.
  PJ* base = proj_crs_get_geodetic_crs(context, crs);
  PJ* to_projected = proj_create_crs_to_crs_from_pj(context, base, crs, nullptr, nullptr);
  proj_destroy(base);
  proj_destroy(crs);
  if (to_projected == nullptr) {
    throw InputError(fmt::format("{}: no conversion from its geodetic CRS ({})", code,
                                 projError(context)));
  }
  proj_->geodetic_to_projected = normalized(context, to_projected);
  // WGS 84 geographic 3D (EPSG:4979) to geocentric (EPSG:4978).
  PJ* to_ecef = proj_create_crs_to_crs(context, "EPSG:4979", "EPSG:4978", nullptr);
  if (to_ecef == nullptr) {
    throw InputError(fmt::format("PROJ database: no EPSG:4979 -> EPSG:4978 conversion ({}); is "
                                 "proj-data installed?",
                                 projError(context)));
  }
  proj_->geodetic_to_ecef = normalized(context, to_ecef);
  if (proj_->geodetic_to_projected == nullptr || proj_->geodetic_to_ecef == nullptr) {
    throw InputError(fmt::format("{}: cannot normalize the axis order ({})", code,
                                 projError(context)));
  }
}

CoordinateConverter::~CoordinateConverter() = default;
CoordinateConverter::CoordinateConverter(CoordinateConverter&&) noexcept = default;
CoordinateConverter& CoordinateConverter::operator=(CoordinateConverter&&) noexcept = default;

Eigen::Vector3d CoordinateConverter::toProjected(const Geodetic& point) const {
  const PJ_COORD c = apply(proj_->geodetic_to_projected, PJ_FWD, point.longitude_deg,
                           point.latitude_deg, point.height_m, "longitude, latitude, height");
  return {c.xyz.x, c.xyz.y, c.xyz.z};
}

Geodetic CoordinateConverter::fromProjected(const Eigen::Vector3d& enh) const {
  const PJ_COORD c = apply(proj_->geodetic_to_projected, PJ_INV, enh.x(), enh.y(), enh.z(),
                           "easting, northing, height");
  return {c.lpz.phi, c.lpz.lam, c.lpz.z};  // degrees: the operation is normalized
}

Eigen::Vector3d CoordinateConverter::toEcef(const Geodetic& point) const {
  const PJ_COORD c = apply(proj_->geodetic_to_ecef, PJ_FWD, point.longitude_deg,
                           point.latitude_deg, point.height_m, "longitude, latitude, height");
  return {c.xyz.x, c.xyz.y, c.xyz.z};
}

Geodetic CoordinateConverter::fromEcef(const Eigen::Vector3d& p_ecef) const {
  const PJ_COORD c =
      apply(proj_->geodetic_to_ecef, PJ_INV, p_ecef.x(), p_ecef.y(), p_ecef.z(), "ECEF x, y, z");
  return {c.lpz.phi, c.lpz.lam, c.lpz.z};
}

Eigen::Matrix3d CoordinateConverter::R_ecef_enu(const Geodetic& origin) {
  const double lat = origin.latitude_deg * kRadPerDeg, lon = origin.longitude_deg * kRadPerDeg;
  Eigen::Matrix3d R;
  R.col(0) << -std::sin(lon), std::cos(lon), 0.0;
  R.col(1) << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat);
  R.col(2) << std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return R;
}

Eigen::Vector3d CoordinateConverter::toEnu(const Geodetic& origin, const Geodetic& point) const {
  return R_ecef_enu(origin).transpose() * (toEcef(point) - toEcef(origin));
}

Geodetic CoordinateConverter::fromEnu(const Geodetic& origin, const Eigen::Vector3d& p_enu) const {
  return fromEcef(toEcef(origin) + R_ecef_enu(origin) * p_enu);
}

GridTangent CoordinateConverter::gridTangent(const Geodetic& origin) const {
  // Central differences over +-1 m: the truncation error (third derivatives, ~d^2 / R^2) and the
  // rounding of grid coordinates (~1e-10 m) are both far below 1e-9 relative.
  constexpr double kStep_m = 1.0;
  auto grid = [&](const Eigen::Vector3d& p_enu) -> Eigen::Vector3d {
    return toProjected(fromEnu(origin, p_enu));
  };
  const Eigen::Vector3d d_east =
      (grid(Eigen::Vector3d(kStep_m, 0, 0)) - grid(Eigen::Vector3d(-kStep_m, 0, 0))) /
      (2.0 * kStep_m);
  GridTangent tangent;
  tangent.scale = std::hypot(d_east.x(), d_east.y());
  const double yaw = std::atan2(d_east.y(), d_east.x());
  tangent.yaw_deg = yaw * kDegPerRad;
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<2, 2>() << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  T.topLeftCorner<2, 2>() *= tangent.scale;
  T.block<3, 1>(0, 3) = toProjected(origin);
  tangent.T_grid_enu = T;
  return tangent;
}

}  // namespace taiga::geo
