#pragma once
// The motion models behind taiga::sim::Motion, and what they share.

#include <cstdint>
#include <memory>

#include "smooth.hpp"
#include "taiga/lie/so3.hpp"
#include "taiga/sim/motion.hpp"

namespace taiga::sim::detail {

std::unique_ptr<TrajectoryModel> makeHandheldMotion(const MotionParams& params, double duration_s,
                                                    std::uint64_t seed, Terrain terrain);
std::unique_ptr<TrajectoryModel> makeHarvesterMotion(const MotionParams& params,
                                                     double duration_s, std::uint64_t seed,
                                                     Terrain terrain);

/// R = Rz(yaw) Ry(pitch) Rx(roll) and the body angular rate from the angles' rates:
/// omega_body = (droll - dyaw sp, dpitch cr + dyaw sr cp, -dpitch sr + dyaw cr cp).
inline void eulerOrientation(const Jet& roll, const Jet& pitch, const Jet& yaw, lie::SO3* R,
                             Eigen::Vector3d* omega_body) {
  *R = lie::SO3::fromRollPitchYaw(roll.v, pitch.v, yaw.v);
  const double sr = std::sin(roll.v), cr = std::cos(roll.v);
  const double sp = std::sin(pitch.v), cp = std::cos(pitch.v);
  *omega_body = Eigen::Vector3d(roll.d - yaw.d * sp, pitch.d * cr + yaw.d * sr * cp,
                                -pitch.d * sr + yaw.d * cr * cp);
}

/// Height of the smooth terrain under a moving point (x(t), y(t)) with its time derivatives:
/// h' = grad . p', h'' = p'^T H p' + grad . p''.
inline Jet groundUnder(const Terrain& terrain, const Jet& x, const Jet& y) {
  Eigen::Vector2d grad;
  Eigen::Matrix2d hess;
  const double h = terrain.smoothHeight(x.v, y.v, &grad, &hess);
  const Eigen::Vector2d dp(x.d, y.d), ddp(x.dd, y.dd);
  return {h, grad.dot(dp), dp.dot(hess * dp) + grad.dot(ddp)};
}

}  // namespace taiga::sim::detail
