#include "taiga/georef/orientation.hpp"

#include <algorithm>

namespace taiga::georef {

lie::SO3 R_enu_ned() {
  Eigen::Matrix3d R;
  R << 0, 1, 0,  //
      1, 0, 0,   //
      0, 0, -1;
  return lie::SO3::fromMatrix(R);
}

std::vector<OrientationSample> absoluteOrientations(const std::vector<ImuSample>& imu,
                                                    const lie::SE3& T_body_imu) {
  const lie::SO3 R_imu_body = T_body_imu.rotation().inverse();
  std::vector<OrientationSample> samples;
  for (const ImuSample& sample : imu) {
    if (!sample.orientation) continue;
    const lie::SO3 R_reference_imu(sample.orientation->q_reference_imu);
    switch (sample.orientation->reference) {
      case OrientationReference::kEnu:
        samples.push_back({sample.t_s, R_reference_imu * R_imu_body});
        break;
      case OrientationReference::kNed:
        samples.push_back({sample.t_s, R_enu_ned() * R_reference_imu * R_imu_body});
        break;
      case OrientationReference::kUnknown:
        break;  // heading arbitrary: not an absolute orientation
    }
  }
  return samples;
}

std::vector<std::optional<lie::SO3>> orientationsAt(const std::vector<OrientationSample>& samples,
                                                    const std::vector<double>& times_s,
                                                    double max_gap_s) {
  std::vector<std::optional<lie::SO3>> result;
  result.reserve(times_s.size());
  for (const double t : times_s) {
    auto after = std::lower_bound(samples.begin(), samples.end(), t,
                                  [](const OrientationSample& s, double time) { return s.t_s < time; });
    if (after == samples.end() || (after == samples.begin() && after->t_s != t)) {
      result.emplace_back();
    } else if (after->t_s == t) {
      result.emplace_back(after->R_enu_body);
    } else {
      const OrientationSample& before = *(after - 1);
      if (after->t_s - before.t_s > max_gap_s) {
        result.emplace_back();
      } else {
        const double s = (t - before.t_s) / (after->t_s - before.t_s);
        result.emplace_back(lie::interpolate(before.R_enu_body, after->R_enu_body, s));
      }
    }
  }
  return result;
}

}  // namespace taiga::georef
