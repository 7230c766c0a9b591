#include "taiga/registration/voxel_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "taiga/core/radix_sort.hpp"
#include "voxel_quanta.hpp"

namespace taiga::registration {

VoxelIndex::VoxelIndex(const std::vector<VoxelKey>& keys) {
  std::uint64_t capacity = 16;
  while (capacity < 2 * keys.size()) capacity *= 2;
  keys_.assign(capacity, kInvalidVoxel);
  values_.assign(capacity, -1);
  mask_ = capacity - 1;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    std::uint64_t slot = hash(keys[i]) & mask_;
    while (keys_[slot] != kInvalidVoxel) slot = (slot + 1) & mask_;
    keys_[slot] = keys[i];
    values_[slot] = static_cast<std::int32_t>(i);
  }
}

bool VoxelStatistics::Sums::operator==(const Sums& o) const {
  return count == o.count && std::equal(s, s + 3, o.s) && std::equal(ss, ss + 6, o.ss);
}

VoxelStatistics::VoxelStatistics(double resolution_m, bool circle_moments)
    : resolution_m_(resolution_m),
      inverse_resolution_(1.0 / resolution_m),
      circle_moments_(circle_moments) {
  if (!(resolution_m > 0.0) || !std::isfinite(resolution_m)) {
    throw std::invalid_argument("VoxelStatistics: resolution_m must be positive, got " +
                                std::to_string(resolution_m));
  }
}

namespace {
// A noise share of a large cell or a loud lidar passes 2^63 quanta^4: beyond 2^62, through
// double -> 128 bits (a library call); below, llround gives the same integer, inline.
Int128 roundedToInt128(double value) {
  if (std::abs(value) < 0x1p62) return std::llround(value);
  return static_cast<Int128>(std::round(value));
}
}  // namespace

void VoxelStatistics::addNoiseShare(const Eigen::Vector3d& p, const std::int64_t q[3],
                                    const BeamNoise& beams, int sign, CircleSums& circle) {
  // The noise's expected share (voxel_statistics.hpp), in quanta, from this point's x (q about
  // the cell centre) and beam; rounded alike when it is removed, so the sums stay exact.
  if (!(beams.sigma_m > 0.0 || beams.sigma_per_m > 0.0)) return;
  const Eigen::Vector3d beam = p - beams.sensor;
  const double range_m = beam.norm();
  const double sigma_m = beams.sigma_m + beams.sigma_per_m * range_m;
  if (!(range_m > 0.0 && sigma_m > 0.0)) return;
  const double sigma_q = sigma_m / kQuantum_m;
  const double s2 = sigma_q * sigma_q;
  const double ux = beam.x() / range_m, uy = beam.y() / range_m, uu = ux * ux + uy * uy;
  const double x = static_cast<double>(q[0]), y = static_cast<double>(q[1]);
  const double ud = ux * x + uy * y;
  circle.noise_xx += sign * std::llround(s2 * ux * ux);
  circle.noise_xy += sign * std::llround(s2 * ux * uy);
  circle.noise_yy += sign * std::llround(s2 * uy * uy);
  circle.noise_xw += sign * roundedToInt128(s2 * (uu * x + 2.0 * ud * ux));
  circle.noise_yw += sign * roundedToInt128(s2 * (uu * y + 2.0 * ud * uy));
  circle.noise_ww += sign * roundedToInt128(s2 * (4.0 * ud * ud + 2.0 * (x * x + y * y) * uu) -
                                            3.0 * s2 * s2 * uu * uu);
}

void VoxelStatistics::update(const Eigen::Vector3d& p, int sign, const BeamNoise* beams) {
  VoxelKey key;
  std::int64_t q[3];
  if (!detail::quantize(p, resolution_m_, inverse_resolution_, key, q)) {
    if (sign > 0) ++skipped_;
    return;
  }
  // One hash lookup per point (a find and then an insert were two: a third of this function).
  const auto it = sign > 0 ? cells_.try_emplace(key).first : cells_.find(key);
  if (it == cells_.end()) {
    throw std::logic_error("VoxelStatistics::remove: a point that was never added");
  }
  Sums& sums = it.value();
  sums.count += sign;
  for (int a = 0; a < 3; ++a) sums.s[a] += sign * q[a];
  sums.ss[0] += sign * q[0] * q[0];
  sums.ss[1] += sign * q[0] * q[1];
  sums.ss[2] += sign * q[0] * q[2];
  sums.ss[3] += sign * q[1] * q[1];
  sums.ss[4] += sign * q[1] * q[2];
  sums.ss[5] += sign * q[2] * q[2];
  if (circle_moments_) {
    // 128 bits: w^2 of one point in a 1 m cell is up to 2.5e19 quanta^4.
    CircleSums& circle = circle_cells_[key];
    const Int128 w = q[0] * q[0] + q[1] * q[1];
    circle.xw += sign * (q[0] * w);
    circle.yw += sign * (q[1] * w);
    circle.ww += sign * (w * w);
    if (beams != nullptr) addNoiseShare(p, q, *beams, sign, circle);
    if (sums.count == 0) circle_cells_.erase(key);
  }
  if (sums.count == 0) cells_.erase(it);
}

void VoxelStatistics::add(std::span<const Eigen::Vector3d> points) {
  for (const auto& p : points) update(p, +1, nullptr);
}

void VoxelStatistics::add(std::span<const Eigen::Vector3d> points, const BeamNoise& beams) {
  for (const auto& p : points) update(p, +1, &beams);
}

void VoxelStatistics::remove(std::span<const Eigen::Vector3d> points) {
  for (const auto& p : points) update(p, -1, nullptr);
}

void VoxelStatistics::remove(std::span<const Eigen::Vector3d> points, const BeamNoise& beams) {
  for (const auto& p : points) update(p, -1, &beams);
}

std::size_t VoxelStatistics::numPoints() const {
  std::size_t n = 0;
  for (const auto& [key, sums] : cells_) n += static_cast<std::size_t>(sums.count);
  return n;
}

CellMoments VoxelStatistics::momentsOf(VoxelKey key, const Sums& sums) const {
  CellMoments m;
  m.key = key;
  m.count = static_cast<std::size_t>(sums.count);
  const double n = static_cast<double>(sums.count);
  const Eigen::Vector3d s(static_cast<double>(sums.s[0]), static_cast<double>(sums.s[1]),
                          static_cast<double>(sums.s[2]));
  m.mean = detail::meanOf(key, resolution_m_, sums.count, sums.s);
  if (sums.count >= 2) {
    Eigen::Matrix3d ss;
    ss << static_cast<double>(sums.ss[0]), static_cast<double>(sums.ss[1]),
        static_cast<double>(sums.ss[2]), static_cast<double>(sums.ss[1]),
        static_cast<double>(sums.ss[3]), static_cast<double>(sums.ss[4]),
        static_cast<double>(sums.ss[2]), static_cast<double>(sums.ss[4]),
        static_cast<double>(sums.ss[5]);
    m.covariance = (ss - s * s.transpose() / n) * (kQuantum_m * kQuantum_m / (n - 1.0));
    if (circle_moments_) circleMoments(sums, circle_cells_.at(key), m);
  }
  return m;
}

void VoxelStatistics::circleMoments(const Sums& sums, const CircleSums& circle,
                                    CellMoments& m) {
  // Raw moments about the cell centre in quanta, then central ones: with
  // a, b the mean, c = a^2 + b^2 and w' = w - 2 a x - 2 b y + c,
  //   E[x' w'] = E[x w] - a E[w] - 2 a E[x^2] - 2 b E[x y] + 2 a c           (and y alike)
  //   E[w'^2]  = E[w^2] + 4 (a^2 E[x^2] + b^2 E[y^2] + 2 a b E[x y]) - 4 (a E[x w] + b E[y w])
  //              + 2 c E[w] - 3 c^2.
  const double n = static_cast<double>(sums.count);
  const double a = static_cast<double>(sums.s[0]) / n;
  const double b = static_cast<double>(sums.s[1]) / n;
  const double xx = static_cast<double>(sums.ss[0]) / n;
  const double xy = static_cast<double>(sums.ss[1]) / n;
  const double yy = static_cast<double>(sums.ss[3]) / n;
  const double xw = static_cast<double>(circle.xw) / n;
  const double yw = static_cast<double>(circle.yw) / n;
  const double ww = static_cast<double>(circle.ww) / n;
  const double w = xx + yy, c = a * a + b * b;
  constexpr double kM3 = kQuantum_m * kQuantum_m * kQuantum_m, kM4 = kM3 * kQuantum_m;
  m.xw = (xw - a * w - 2.0 * a * xx - 2.0 * b * xy + 2.0 * a * c) * kM3;
  m.yw = (yw - b * w - 2.0 * b * yy - 2.0 * a * xy + 2.0 * b * c) * kM3;
  m.ww = (ww + 4.0 * (a * a * xx + b * b * yy + 2.0 * a * b * xy) - 4.0 * (a * xw + b * yw) +
          2.0 * c * w - 3.0 * c * c) *
         kM4;
  // The noise's share about the mean: the same conversion is linear in the raw moments, so the
  // share converts by its linear part (the mean is not changed by zero-mean noise).
  const double nxx = static_cast<double>(circle.noise_xx) / n;
  const double nxy = static_cast<double>(circle.noise_xy) / n;
  const double nyy = static_cast<double>(circle.noise_yy) / n;
  const double nxw = static_cast<double>(circle.noise_xw) / n;
  const double nyw = static_cast<double>(circle.noise_yw) / n;
  const double nww = static_cast<double>(circle.noise_ww) / n;
  const double nw = nxx + nyy;
  constexpr double kM2 = kQuantum_m * kQuantum_m;
  m.noise_xx << nxx * kM2, nxy * kM2, nxy * kM2, nyy * kM2;
  m.noise_xw = (nxw - a * nw - 2.0 * a * nxx - 2.0 * b * nxy) * kM3;
  m.noise_yw = (nyw - b * nw - 2.0 * b * nyy - 2.0 * a * nxy) * kM3;
  m.noise_ww = (nww + 4.0 * (a * a * nxx + b * b * nyy + 2.0 * a * b * nxy) -
                4.0 * (a * nxw + b * nyw) + 2.0 * c * nw) *
               kM4;
}

std::vector<CellMoments> VoxelStatistics::moments(std::size_t min_points) const {
  // Sorting (key, sums) pairs instead of keys avoids a hash lookup per cell afterwards.
  std::vector<std::pair<VoxelKey, const Sums*>> cells;
  cells.reserve(cells_.size());
  for (const auto& [key, sums] : cells_) {
    if (static_cast<std::size_t>(sums.count) >= min_points) cells.emplace_back(key, &sums);
  }
  radixSortByVoxelKey(cells);
  std::vector<CellMoments> out;
  out.reserve(cells.size());
  for (const auto& [key, sums] : cells) out.push_back(momentsOf(key, *sums));
  return out;
}

bool VoxelStatistics::operator==(const VoxelStatistics& other) const {
  return resolution_m_ == other.resolution_m_ && cells_ == other.cells_ &&
         circle_cells_ == other.circle_cells_;
}

}  // namespace taiga::registration
