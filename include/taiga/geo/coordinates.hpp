#pragma once
// Geodesy through PROJ: geodetic coordinates (latitude, longitude, ellipsoidal height) to and from
// a projected CRS given by its EPSG code (EPSG:3067 ETRS-TM35FIN by default, UTM zones such as
// EPSG:32635), Earth-centred Earth-fixed (ECEF) coordinates, and a local east-north-up (ENU)
// frame at an origin.
//
// Datum: the geodetic coordinates are in the datum of the projected CRS (ETRS89 for EPSG:3067,
// WGS84 for EPSG:326xx). WGS84 and ETRS89 are taken as the same here: they differ by about 0.8 m
// in 2025 through plate motion, a time-dependent transformation that needs the epoch of the fixes
// and is the georeferencing module's business. ECEF uses the WGS84 ellipsoid (GRS80's differs in
// the semi-minor axis by 0.1 mm). Heights are ellipsoidal throughout (no geoid).
//
// A converter holds PROJ objects that are not thread-safe: use one converter per thread.

#include <Eigen/Core>
#include <memory>
#include <string>

namespace taiga::geo {

struct Geodetic {
  double latitude_deg = 0.0;   ///< positive north
  double longitude_deg = 0.0;  ///< positive east
  double height_m = 0.0;       ///< above the ellipsoid
};

/// The projected CRS's grid at a point, from the projection's Jacobian there: the grid is the
/// local ENU plane rotated by the meridian convergence and scaled by the point scale factor.
struct GridTangent {
  /// Angle from grid easting to local east, counterclockwise seen from above, deg:
  /// [E, N] - [E0, N0] = scale * Rz(yaw) * [e, n] to first order. It is the meridian convergence
  /// (from true north to grid north, clockwise), about (lon - lon_0) * sin(lat) for a transverse
  /// Mercator grid: negative west of the central meridian.
  double yaw_deg = 0.0;
  /// Grid metres per local metre at the point: the projection's point scale factor (grid
  /// distance / ellipsoid distance, e.g. 0.9996 on a UTM central meridian) times the height
  /// reduction R / (R + h) (19 ppm per 120 m of ellipsoidal height).
  double scale = 1.0;
  /// The tangent-plane approximation as a 4x4 affine map from ENU at the point to the grid:
  /// [E, N, h]^T = T * [e, n, u, 1]^T with the 3x3 block diag(scale * Rz(yaw), 1): heights are
  /// not scaled. Its error grows with the square of the distance from the point (terms like
  /// d^2 tan(lat) / R and the Earth's curvature d^2 / 2R in h): 0.2 mm at 50 m, 1.8 mm at 150 m at
  /// 61 N 24.5 E in EPSG:3067
  /// (docs/simulator.md, tests/geo).
  Eigen::Matrix4d T_grid_enu = Eigen::Matrix4d::Identity();
};

class CoordinateConverter {
 public:
  /// InputError naming the code when PROJ does not know it or it is not a projected CRS.
  explicit CoordinateConverter(int epsg = 3067);
  ~CoordinateConverter();
  CoordinateConverter(CoordinateConverter&&) noexcept;
  CoordinateConverter& operator=(CoordinateConverter&&) noexcept;

  int epsg() const { return epsg_; }
  /// The CRS's name in the EPSG database, e.g. "ETRS89 / TM35FIN(E,N)".
  const std::string& crsName() const { return name_; }
  /// The CRS as OGC WKT1 (GDAL's flavour), for LAS headers.
  const std::string& wkt() const { return wkt_; }

  /// Easting, northing (m) and the unchanged ellipsoidal height (m).
  Eigen::Vector3d toProjected(const Geodetic& point) const;
  Geodetic fromProjected(const Eigen::Vector3d& easting_northing_height) const;

  Eigen::Vector3d toEcef(const Geodetic& point) const;
  Geodetic fromEcef(const Eigen::Vector3d& p_ecef) const;

  /// Local ENU coordinates (m) of `point` in the frame at `origin` (its x east, y north, z along
  /// the ellipsoid normal), exact through ECEF.
  Eigen::Vector3d toEnu(const Geodetic& origin, const Geodetic& point) const;
  Geodetic fromEnu(const Geodetic& origin, const Eigen::Vector3d& p_enu) const;
  /// Rotation whose columns are the east, north and up unit vectors in ECEF.
  static Eigen::Matrix3d R_ecef_enu(const Geodetic& origin);

  /// The grid's scale and rotation at `origin`, and the tangent-plane map T_grid_enu.
  GridTangent gridTangent(const Geodetic& origin) const;

 private:
  struct Proj;
  int epsg_;
  std::string name_;
  std::string wkt_;
  std::unique_ptr<Proj> proj_;
};

}  // namespace taiga::geo
