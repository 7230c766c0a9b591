#pragma once
// The IMU's own absolute orientation (9-axis modules, AHRS) as R_enu_body at the fixes' times,
// for pf6.
//
// ImuSample::orientation holds q_reference_imu (sensor_samples.hpp) with its reference frame:
// ENU (ROS REP-103) is used as it is; NED is turned into ENU with R_enu_ned (x_enu = y_ned,
// y_enu = x_ned, z_enu = -z_ned); an unknown reference (gravity-aligned, arbitrary heading) is not
// an absolute orientation and is not used. R_enu_body = R_enu_reference * R_reference_imu *
// R_body_imu^T.

#include <optional>
#include <vector>

#include "taiga/core/sensor_samples.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga::georef {

/// R_enu_ned: rotates NED vectors into ENU (a proper rotation, det +1).
lie::SO3 R_enu_ned();

/// One absolute orientation sample.
struct OrientationSample {
  double t_s = 0.0;
  lie::SO3 R_enu_body;
};

/// The samples of `imu` (time order) that carry an ENU or NED orientation, as R_enu_body.
std::vector<OrientationSample> absoluteOrientations(const std::vector<ImuSample>& imu,
                                                    const lie::SE3& T_body_imu);

/// The orientation at each of `times_s`, interpolated on SO(3) between the neighbouring samples;
/// empty where the time is outside the samples or the neighbours are more than max_gap_s apart.
std::vector<std::optional<lie::SO3>> orientationsAt(const std::vector<OrientationSample>& samples,
                                                    const std::vector<double>& times_s,
                                                    double max_gap_s = 0.1);

}  // namespace taiga::georef
