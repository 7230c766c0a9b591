#include "taiga/sim/realism.hpp"

#include <fmt/format.h>

#include "taiga/core/errors.hpp"

namespace taiga::sim {
namespace {

// Sources of the values (docs/simulator.md, "Realism", has the table):
// - ICM-20948 datasheet (the IMU inside Ouster sensors): scale-factor tolerance +-1.5 % (gyro),
//   +-0.5 % (accelerometer, initial), cross-axis sensitivity +-2 % (about 1.1 deg), full scales
//   +-2/4/8/16 g and +-250/500/1000/2000 deg/s; Ouster firmware streams the IMU at 100 Hz.
// - Allan-deviation studies of consumer MEMS IMUs find white noise 1.5-3x and bias random walk
//   2-10x the datasheet's typical figure, and bias instability of 5-20 deg/h (gyro) and
//   0.05-0.1 mg (accelerometer) with correlation times of tens to hundreds of seconds.
// - MEMS gyro g-sensitivity: 0.01-0.1 deg/s/g (vendor application notes).
// - Lidar-IMU extrinsics measured from a drawing: a few cm and 1-3 deg; time offsets between a
//   lidar and an unsynchronized IMU: 5-50 ms (LI-Init, Kalibr issue trackers); free-running
//   crystal clocks: +-20-50 ppm.
// - Ouster OS0 datasheet: range precision 1-3 cm near, up to about 5 cm for dark targets at the
//   edge of the range; UDP packet loss on a loaded host 0.1-1 %.
// - Wind: conifer stems sway at 0.2-0.4 Hz, crowns by decimetres in a moderate breeze.
// - GNSS receivers' reported accuracy (e.g. NMEA GST, u-blox hAcc) comes from their own
//   residuals and is only loosely tied to the actual error under canopy: off by 20-40 % from
//   fix to fix is assumed here (no published figure was found to take instead).

void typical(Scenario& s) {
  ImuParams& imu = s.imu;
  imu.noise_density_factor = 2.0;
  imu.bias_walk_factor = 2.0;
  imu.accel_bias_instability_mps2 = 5e-4;  // 0.05 mg
  imu.gyro_bias_instability_radps = 5e-5;  // 10 deg/h
  imu.bias_correlation_s = 100.0;
  imu.scale_factor_error = 0.005;
  imu.misalignment_deg = 0.3;
  imu.gyro_g_sensitivity_deg_s_per_g = 0.03;
  imu.accel_range_g = 4.0;
  imu.gyro_range_deg_s = 500.0;
  imu.timestamp_jitter_s = 2e-4;
  LidarParams& lidar = s.lidar;
  lidar.dropout_probability = 0.02;
  lidar.range_noise_at_limit_m = 0.03;
  lidar.packet_loss_probability = 0.001;
  RigErrorParams& rig = s.rig;
  rig.extrinsic_rotation_error_deg = 2.0;
  rig.extrinsic_translation_error_m = 0.03;
  rig.lidar_time_offset_s = 0.010;
  rig.lidar_clock_drift_ppm = 10.0;
  s.forest.wind_sway_m = 0.05;
  s.gnss.reported_sigma_noise = 0.2;
}

void harsh(Scenario& s) {
  ImuParams& imu = s.imu;
  imu.rate_hz = 100.0;  // the Ouster's internal IMU
  imu.noise_density_factor = 3.0;
  imu.bias_walk_factor = 3.0;
  imu.accel_turn_on_bias *= 2.0;
  imu.gyro_turn_on_bias *= 2.0;
  imu.accel_bias_instability_mps2 = 1e-3;  // 0.1 mg
  imu.gyro_bias_instability_radps = 1e-4;  // 20 deg/h
  imu.bias_correlation_s = 60.0;
  imu.scale_factor_error = 0.015;
  imu.misalignment_deg = 1.0;
  imu.gyro_g_sensitivity_deg_s_per_g = 0.1;
  imu.accel_range_g = 2.0;
  imu.gyro_range_deg_s = 250.0;
  imu.timestamp_jitter_s = 1e-3;
  LidarParams& lidar = s.lidar;
  lidar.dropout_probability = 0.05;
  lidar.range_noise_at_limit_m = 0.06;
  lidar.packet_loss_probability = 0.01;
  RigErrorParams& rig = s.rig;
  rig.extrinsic_rotation_error_deg = 5.0;
  rig.extrinsic_translation_error_m = 0.08;
  rig.lidar_time_offset_s = 0.040;
  rig.lidar_clock_drift_ppm = 50.0;
  s.forest.wind_sway_m = 0.2;
  s.gnss.reported_sigma_noise = 0.4;
}

struct Preset {
  const char* name;
  void (*apply)(Scenario&);
};
constexpr Preset kPresets[] = {
    {"ideal", [](Scenario&) {}}, {"typical", typical}, {"harsh", harsh}};

}  // namespace

std::vector<std::string> realismNames() {
  std::vector<std::string> names;
  for (const Preset& p : kPresets) names.emplace_back(p.name);
  return names;
}

void applyRealism(const std::string& preset, Scenario& scenario) {
  for (const Preset& p : kPresets) {
    if (preset != p.name) continue;
    p.apply(scenario);
    scenario.realism = p.name;
    return;
  }
  throw InputError(fmt::format("--realism {}: unknown preset; expected one of {}", preset,
                               fmt::join(realismNames(), ", ")));
}

}  // namespace taiga::sim
