#include "taiga/sim/gnss.hpp"

#include <cmath>
#include <numbers>

#include "taiga/core/angles.hpp"
#include "taiga/sim/random.hpp"

namespace taiga::sim {
namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kA = 6378137.0;            // WGS84 semi-major axis, m
constexpr double kF = 1.0 / 298.257223563;  // WGS84 flattening
constexpr double kE2 = kF * (2.0 - kF);     // first eccentricity squared

Eigen::Vector3d toEcef(const Geodetic& g) {
  const double lat = g.latitude_deg * kRadPerDeg, lon = g.longitude_deg * kRadPerDeg;
  const double n = kA / std::sqrt(1.0 - kE2 * std::sin(lat) * std::sin(lat));
  return {(n + g.height_m) * std::cos(lat) * std::cos(lon),
          (n + g.height_m) * std::cos(lat) * std::sin(lon),
          (n * (1.0 - kE2) + g.height_m) * std::sin(lat)};
}

Geodetic fromEcef(const Eigen::Vector3d& x) {
  const double lon = std::atan2(x.y(), x.x());
  const double p = std::hypot(x.x(), x.y());
  double lat = std::atan2(x.z(), p * (1.0 - kE2));
  double h = 0.0;
  for (int i = 0; i < 10; ++i) {  // converges to well below a millimetre near the surface
    const double n = kA / std::sqrt(1.0 - kE2 * std::sin(lat) * std::sin(lat));
    h = p / std::cos(lat) - n;
    lat = std::atan2(x.z(), p * (1.0 - kE2 * n / (n + h)));
  }
  return {lat / kRadPerDeg, lon / kRadPerDeg, h};
}

/// Columns: east, north, up unit vectors in ECEF.
Eigen::Matrix3d ecefFromEnu(const Geodetic& origin) {
  const double lat = origin.latitude_deg * kRadPerDeg, lon = origin.longitude_deg * kRadPerDeg;
  Eigen::Matrix3d R;
  R.col(0) << -std::sin(lon), std::cos(lon), 0.0;
  R.col(1) << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat);
  R.col(2) << std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return R;
}
}  // namespace

Geodetic enuToGeodetic(const Geodetic& origin, const Eigen::Vector3d& p_enu) {
  return fromEcef(toEcef(origin) + ecefFromEnu(origin) * p_enu);
}

Eigen::Vector3d geodeticToEnu(const Geodetic& origin, const Geodetic& point) {
  return ecefFromEnu(origin).transpose() * (toEcef(point) - toEcef(origin));
}

GnssSimulator::GnssSimulator(GnssParams params, std::uint64_t seed)
    : params_(params), seed_(streamSeed(seed, "gnss")) {
  markov_ = Eigen::Vector3d(hashNormal(seed_, 0, 1, 0), hashNormal(seed_, 0, 1, 1),
                            hashNormal(seed_, 0, 1, 2));
}

double GnssSimulator::canopyCover(const Scene& scene, const Eigen::Vector3d& p_world) {
  int blocked = 0, total = 0;
  for (int ring = 0; ring < 3; ++ring) {
    const double elevation = (25.0 + 25.0 * ring) * kRadPerDeg;
    const int n = 10 - 3 * ring;  // 10, 7, 4 (+ zenith below)
    for (int i = 0; i < n; ++i) {
      const double az = 2.0 * kPi * (i + 0.5 * ring) / n;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(az),
                              std::cos(elevation) * std::sin(az), std::sin(elevation));
      blocked += scene.castRay(p_world, d, 0.05, 60.0) ? 1 : 0;
      ++total;
    }
  }
  blocked += scene.castRay(p_world, Eigen::Vector3d::UnitZ(), 0.05, 60.0) ? 1 : 0;
  ++total;
  return static_cast<double>(blocked) / total;
}

std::optional<GnssFix> GnssSimulator::next(const WalkingMotion& motion, const Scene& scene,
                                           double time_offset_s) {
  const double t = nextTime_s();
  const std::uint64_t k = k_++;
  const Eigen::Vector3d p_world = motion.at(t).T_world_body.translation();
  const double cover = canopyCover(scene, p_world);
  const double sigma_h =
      params_.sigma_open_horizontal_m + cover * params_.sigma_canopy_horizontal_m;
  const double sigma_v = params_.vertical_factor * sigma_h;
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  if (params_.noise) {
    const double phi = std::exp(-1.0 / (params_.rate_hz * params_.correlation_time_s));
    const Eigen::Vector3d n(hashNormal(seed_, k, 2, 0), hashNormal(seed_, k, 2, 1),
                            hashNormal(seed_, k, 2, 2));
    if (k > 0) markov_ = phi * markov_ + std::sqrt(1.0 - phi * phi) * n;
    error = Eigen::Vector3d(sigma_h * markov_.x(), sigma_h * markov_.y(), sigma_v * markov_.z());
    if (jump_fixes_left_ > 0) {
      --jump_fixes_left_;
    } else if (hashUniform(seed_, k, 3) < params_.multipath_probability * cover) {
      const double az = 2.0 * kPi * hashUniform(seed_, k, 4);
      const double size = params_.multipath_jump_m * (0.3 + 1.7 * hashUniform(seed_, k, 5));
      jump_m_ = Eigen::Vector3d(size * std::cos(az), size * std::sin(az),
                                0.5 * size * hashNormal(seed_, k, 6));
      jump_fixes_left_ = 1 + static_cast<int>(hashUniform(seed_, k, 7) * 3.0 * params_.rate_hz);
    } else {
      jump_m_.setZero();
    }
    error += jump_m_;
  }
  truth_ = {.t_s = t + time_offset_s,
            .sigma_horizontal_m = sigma_h,
            .sigma_vertical_m = sigma_v,
            .error_enu_m = error,
            .multipath = !jump_m_.isZero(),
            .outage = params_.noise && hashUniform(seed_, k, 8) < params_.outage_probability * cover};
  if (truth_.outage) return std::nullopt;
  Eigen::Vector3d p_enu = p_world;
  if (params_.world_yaw_deg != 0.0) {  // world x is world_yaw_deg counterclockwise from east
    const double yaw = params_.world_yaw_deg * kRadPerDeg;
    p_enu.x() = std::cos(yaw) * p_world.x() - std::sin(yaw) * p_world.y();
    p_enu.y() = std::sin(yaw) * p_world.x() + std::cos(yaw) * p_world.y();
  }
  const Geodetic g = enuToGeodetic(origin(), p_enu + error);  // the error is east-north-up
  GnssFix fix;
  fix.t_s = t + time_offset_s;
  fix.latitude_deg = g.latitude_deg;
  fix.longitude_deg = g.longitude_deg;
  fix.height_ellipsoid_m = g.height_m;
  const double report_error =
      params_.noise && params_.reported_sigma_noise > 0.0
          ? std::exp(params_.reported_sigma_noise * hashNormal(seed_, k, 9, 0))
          : 1.0;
  const double reported_h = params_.reported_sigma_factor * report_error * sigma_h,
               reported_v = params_.reported_sigma_factor * report_error * sigma_v;
  fix.covariance_enu_m2 =
      Eigen::Vector3d(reported_h * reported_h, reported_h * reported_h, reported_v * reported_v)
          .asDiagonal();
  fix.covariance_type = GnssCovarianceType::kDiagonalKnown;
  fix.status = GnssStatus::kFix;
  return fix;
}

}  // namespace taiga::sim
