#pragma once
// Scenarios of the simulator: what forest is generated, how the sensor moves, and how the sensors
// behave. Every field has a unit in its name or comment; defaults are those of the `mixed`
// scenario with a handheld Ouster OS0-128 (see docs/simulator.md).

#include <cstdint>
#include <string>
#include <vector>

namespace taiga::sim {

/// Share of each tree species in a stand; the shares are normalized when drawing.
struct SpeciesMix {
  double pine = 0.4;
  double spruce = 0.35;
  double birch = 0.25;
};

struct ForestParams {
  double stems_per_ha = 850.0;        ///< mature trees (DBH >= 8 cm) per hectare
  double dbh_mean_m = 0.22;           ///< mean diameter at breast height (1.3 m), m
  double dbh_sigma_m = 0.08;          ///< spread of DBH, m (clamped to 0.08 .. 0.50 m)
  SpeciesMix species;                 ///< share of pine, spruce and birch
  double saplings_per_ha = 1500.0;    ///< young trees 0.5 .. 4 m tall
  double shrubs_per_ha = 800.0;       ///< low clumps of foliage (0.1 .. 0.6 m high)
  double boulders_per_ha = 30.0;      ///< rocks 0.3 .. 1.5 m across
  double logs_per_ha = 25.0;          ///< fallen stems lying on the ground
  double terrain_slope = 0.04;        ///< mean gradient of the terrain (m per m)
  double terrain_undulation_m = 1.5;  ///< amplitude of the long-wave terrain relief, m
  double micro_relief_m = 0.12;       ///< amplitude of the short-wave relief (hummocks), m
  double road_half_width_m = 0.0;     ///< > 0: a strip road along the world x axis without trees
  double path_clearance_m = 1.0;      ///< no stem closer than this to the walked path, m
  /// Wind: horizontal sway of stems, branches and foliage (0: the forest stands still). The
  /// amplitude at 20 m above the ground, m; it grows linearly from 2 m up, doubled for branches
  /// and foliage (docs/simulator.md, "Realism").
  double wind_sway_m = 0.0;
  double wind_period_s = 4.0;  ///< period of the sway (conifers sway at about 0.2-0.4 Hz), s
};

/// Which rig moves through the forest.
enum class MotionModel {
  kHandheld,   ///< a person walking with the scanner on a stick
  kHarvester,  ///< a forest harvester on a strip road (needs forest.road_half_width_m > 0)
};

struct MotionParams {
  MotionModel model = MotionModel::kHandheld;
  double speed_mps = 1.35;             ///< mean walking speed, m/s
  double sensor_height_m = 2.2;        ///< sensor (body) height above the ground, m
  double loop_aspect = 1.0;            ///< loop's y radius / x radius (strip road: thin loop)
  /// 0: the loop is an ellipse (whose ends turn on a radius of Ry^2 / Rx: 3 cm on the strip
  /// road's); k > 0: a stadium whose sides straighten with k and whose ends are half circles of
  /// radius about Ry (k = 4: 0.9 Ry), handheld_motion.cpp
  double loop_straightness = 0.0;
  double max_loop_length_m = 300.0;    ///< longer recordings walk the loop again
  double shape_perturbation = 0.18;    ///< relative amplitude of the loop's wiggles
  /// 1: one loop; 3 or 4: a cloverleaf of that many lobes that all pass through the start
  /// area (max_loop_length_m is then the length of the whole cloverleaf)
  int loop_lobes = 1;
  double lobe_size_variation = 0.3;    ///< relative size difference of the lobes (0 .. 0.6)
  double speed_variation = 0.25;       ///< relative amplitude of speed changes
  double look_around_deg = 25.0;       ///< slow yaw swings about the walking direction, deg
  double look_around_fast_deg = 10.0;  ///< faster yaw swings, deg
  double step_frequency_hz = 1.8;      ///< gait frequency of the vertical bob, Hz
  double bob_m = 0.025;                ///< vertical bob amplitude, m
  double sway_m = 0.03;                ///< horizontal sway amplitude, m
  double roll_sway_deg = 3.0;          ///< roll oscillation at half the step frequency, deg
  double pitch_sway_deg = 2.5;         ///< pitch oscillation at the step frequency, deg
  double pitch_mean_deg = -3.0;        ///< mean pitch (nose down negative about y), deg
  // Pauses of the operator: speed goes smoothly to zero, stays there, and comes back.
  double pause_interval_s = 30.0;  ///< mean walking time between pauses, s (0: no pauses)
  double pause_min_s = 2.0;        ///< shortest standing time of a pause, s
  double pause_max_s = 6.0;        ///< longest standing time of a pause, s
  double pause_ramp_s = 1.5;       ///< time to slow down to a stop, and to get going again, s
  // Fast turns: the operator looks aside quickly (a smooth bump in yaw) and back.
  double fast_turn_interval_s = 15.0;  ///< mean time between fast turns, s (0: none)
  double fast_turn_min_deg = 60.0;     ///< smallest turn away from the walking direction, deg
  double fast_turn_max_deg = 120.0;    ///< largest turn, deg
  /// peak yaw rate during a turn, everything included, deg/s (each turn draws 75-100 % of it)
  double fast_turn_rate_deg_s = 90.0;
  // Harvester (model = kHarvester): drives along the strip road (world x) from tree to tree.
  double harvester_speed_min_mps = 0.3;      ///< slowest drive between trees, m/s
  double harvester_speed_max_mps = 1.0;      ///< fastest drive, m/s
  double harvester_drive_min_m = 4.0;        ///< shortest drive from one tree stop to the next, m
  double harvester_drive_max_m = 12.0;       ///< longest drive, m
  double harvester_stop_min_s = 20.0;        ///< shortest stop to fell and process a tree, s
  double harvester_stop_max_s = 60.0;        ///< longest stop, s
  double harvester_ramp_s = 2.0;             ///< time to speed up from, or slow down to, 0, s
  double harvester_reverse_probability = 0.3;  ///< after a stop: back up a few metres first
  double harvester_reverse_max_m = 4.0;        ///< longest reversing, m (shortest: 1.5 m)
  double harvester_lateral_m = 0.3;  ///< slow side-to-side weave on the road, amplitude, m
  /// vibration bursts while a tree is handled: peak linear acceleration per axis (vertical: 1.5x)
  double harvester_vibration_mps2 = 4.0;
  double harvester_vibration_rate_deg_s = 4.0;  ///< peak angular rate per axis, deg/s
  double harvester_vibration_min_hz = 10.0;     ///< lowest vibration frequency, Hz
  double harvester_vibration_max_hz = 30.0;     ///< highest vibration frequency, Hz

  /// InputError naming the field (`motion.<field>`) for values out of range.
  void validate() const;
};

struct LidarParams {
  /// Beam table and frames: one of the sensor models built into taiga (`os0-128`, see
  /// sensor_models.hpp), used when metadata_json is empty.
  std::string model = "os0-128";
  /// An Ouster metadata JSON (beam angles, frames) instead of the built-in model; a file that
  /// cannot be read is an error.
  std::string metadata_json;
  int beams = 0;              ///< rows; fewer than the table's: evenly subsampled; 0: all
  int columns = 1024;         ///< firings per rotation (512, 1024, 2048)
  double rotation_hz = 10.0;  ///< frames per second
  double min_range_m = 0.5;     ///< closer returns are suppressed (operator, stick)
  double max_range_m = 45.0;    ///< for a bright target (reflectivity 0.8) at normal incidence
  double range_noise_m = 0.01;  ///< 1-sigma range noise at 0 m
  double range_noise_per_m = 0.0005;  ///< additional 1-sigma noise per metre of range
  double beam_divergence_deg = 0.35;  ///< full angle of the beam footprint
  int sub_rays = 4;                   ///< rays per beam to model the footprint (1 = no divergence)
  double dropout_probability = 0.01;  ///< random missing returns
  /// additional 1-sigma range noise of a return at its detection limit, m; it grows with the
  /// square of range / detection limit (weak, dark or far returns are noisier)
  double range_noise_at_limit_m = 0.0;
  double packet_loss_probability = 0.0;  ///< share of lost UDP packets (16 columns each)
  bool noise = true;                  ///< false: exact ranges, no dropouts (for tests)
};

struct ImuParams {
  double rate_hz = 200.0;
  /// Continuous-time white-noise densities and bias random walks as the datasheet states them
  /// (a consumer/industrial MEMS unit such as the ICM-20948 inside Ouster sensors; see
  /// docs/simulator.md); rig.yaml gets these. The simulated ones are these times the factors
  /// below.
  double accel_noise_density = 2.0e-3;     ///< m/s^2/sqrt(Hz)
  double gyro_noise_density = 2.5e-4;      ///< rad/s/sqrt(Hz)
  double accel_bias_random_walk = 1.0e-4;  ///< m/s^3/sqrt(Hz)
  double gyro_bias_random_walk = 1.0e-5;   ///< rad/s^2/sqrt(Hz)
  double accel_turn_on_bias = 0.05;        ///< 1-sigma bias per axis at start, m/s^2
  double gyro_turn_on_bias = 2.0e-3;       ///< 1-sigma bias per axis at start, rad/s
  double gravity_mps2 = 9.81;
  // Errors the datasheet and rig.yaml do not state (docs/simulator.md, "Realism").
  double noise_density_factor = 1.0;  ///< true / stated white-noise densities
  double bias_walk_factor = 1.0;      ///< true / stated bias random walks
  double accel_bias_instability_mps2 = 0.0;  ///< 1-sigma Gauss-Markov bias, m/s^2
  double gyro_bias_instability_radps = 0.0;  ///< 1-sigma Gauss-Markov bias, rad/s
  double bias_correlation_s = 100.0;         ///< time constant of the Gauss-Markov biases, s
  double scale_factor_error = 0.0;           ///< 1-sigma per-axis scale error (0.01 = 1 %)
  double misalignment_deg = 0.0;             ///< 1-sigma axis non-orthogonality, deg
  double gyro_g_sensitivity_deg_s_per_g = 0.0;  ///< 1-sigma gyro error per g of specific force
  double accel_range_g = 0.0;                ///< > 0: the accelerometer clips at +-this, g
  double gyro_range_deg_s = 0.0;             ///< > 0: the gyroscope clips at +-this, deg/s
  double timestamp_jitter_s = 0.0;           ///< 1-sigma error of each sample's stamp, s
  bool noise = true;  ///< false: exact specific force and angular rate
  /// true: each sample carries the orientation of an internal attitude filter (AHRS without a
  /// magnetometer), as 9-axis IMU modules report it; false: a 6-axis IMU such as the one inside
  /// Ouster sensors (sensor_msgs/Imu orientation_covariance[0] = -1). The reported orientation is
  /// q_enu_imu (REP-103, what the readers assume) perturbed by the errors below.
  bool orientation_output = false;
  double orientation_tilt_error_deg = 0.7;  ///< 1-sigma roll and pitch error, deg
  double orientation_tilt_correlation_s = 60.0;  ///< Gauss-Markov time of the tilt error, s
  /// heading drift (random walk): sigma grows as this x sqrt(t), deg/sqrt(s) (0.15: ~3 deg in 7 min)
  double orientation_heading_walk_deg_per_sqrt_s = 0.15;
  /// constant heading error, deg: the filter's heading is arbitrary without a magnetometer
  double orientation_heading_offset_deg = 35.0;
};

struct GnssParams {
  double rate_hz = 1.0;
  double origin_latitude_deg = 61.0;  ///< geodetic position of the world origin (WGS84)
  double origin_longitude_deg = 24.5;
  double origin_height_m = 120.0;          ///< ellipsoidal height of the world origin, m
  /// Heading of the world frame: angle from local east to world x, counterclockwise, deg
  /// (0: the world frame is east-north-up at the origin)
  double world_yaw_deg = 0.0;
  int georef_epsg = 3067;  ///< projected CRS of georef_truth.yaml (ETRS-TM35FIN)
  double sigma_open_horizontal_m = 0.4;    ///< 1-sigma error without canopy
  double sigma_canopy_horizontal_m = 2.5;  ///< additional 1-sigma error under full canopy
  double vertical_factor = 1.8;            ///< vertical sigma / horizontal sigma
  double correlation_time_s = 30.0;        ///< first-order Gauss-Markov time constant of the error
  double multipath_probability = 0.03;     ///< per fix under full canopy: start of a multipath jump
  double multipath_jump_m = 15.0;          ///< typical size of a jump, m
  double outage_probability = 0.08;        ///< per fix under full canopy: no fix
  double reported_sigma_factor = 0.7;      ///< reported / true sigma (< 1: optimistic receiver)
  /// The reported sigma is further off by a factor exp(N(0, s^2)) per fix, s this value: a
  /// receiver's sigma is an estimate too, only loosely tied to the error it describes.
  double reported_sigma_noise = 0.0;
  bool noise = true;
};

/// How the rig as built differs from the rig.yaml a user would write (docs/simulator.md,
/// "Realism"). rig.yaml states the nominal values; rig_truth.yaml the true ones.
struct RigErrorParams {
  /// angle of the rotation between the true and the stated T_body_lidar (axis drawn from the
  /// seed), deg
  double extrinsic_rotation_error_deg = 0.0;
  double extrinsic_translation_error_m = 0.0;  ///< length of the lever-arm error, m
  /// the true rig.lidar_time_offset_s: lidar stamps are late on the IMU clock by minus this
  /// (what must be added to lidar times to put them on the IMU clock), s
  double lidar_time_offset_s = 0.0;
  double lidar_clock_drift_ppm = 0.0;  ///< the lidar clock runs fast against the IMU's, ppm
};

/// What the recording holds, for the kinds of recordings users have (docs/simulator.md,
/// "Kinds of recordings").
struct OutputParams {
  /// `ouster`: the Ouster driver's organized cloud with per-point `t`; `velodyne`: a flat cloud
  /// with `ring` and `time` (velodyne_pointcloud); `deskewed`: a flat x y z intensity cloud
  /// already deskewed (with the true motion) into the lidar frame at the header stamp, the
  /// scan's start, without a time field; `untimed`: the same flat cloud as the sensor swept it
  /// (not deskewed), as a driver that drops the time field publishes it.
  std::string point_layout = "ouster";
  int scan_stride = 1;  ///< keep every n-th scan (5: a 2 Hz keyframe sequence from a 10 Hz lidar)
  bool imu = true;      ///< write the IMU topic
  bool gnss = true;     ///< write the GNSS topic
  /// Also write capture.pcap + capture.json, the scans and IMU samples as an Ouster sensor's UDP
  /// packets in this lidar profile (LEGACY, RNG19_RFL8_SIG16_NIR16, RNG15_RFL8_NIR8); empty: no
  /// capture.
  std::string pcap_profile;
};

/// Faults injected into the recording, to test that a run says what went wrong (the
/// no-silent-failure issue; docs/simulator.md, "Faults"). Each is off at its default. Times are
/// the motion's, s after the recording's start.
struct FaultParams {
  double imu_gap_start_s = 0.0;  ///< no IMU samples from here ...
  double imu_gap_s = 0.0;        ///< ... for this long (0: no gap)
  double packet_burst_start_s = 0.0;  ///< the scans from here ...
  int packet_burst_scans = 0;         ///< ... this many of them (0: none) ...
  double packet_burst_loss = 0.9;     ///< ... lose this share of their 16-column packets
  /// The scan that starts here (0: none) is replaced by the one simulated at splice_from_s, from
  /// another place, stamped as the scan it replaces.
  double splice_at_s = 0.0;
  double splice_from_s = 0.0;
  /// The scans that start in [open_field_start_s, + open_field_s) see only the ground, as in a
  /// clearing: returns more than 0.3 m above the terrain are dropped (0 s: none).
  double open_field_start_s = 0.0;
  double open_field_s = 0.0;
};

struct Scenario {
  std::string name = "mixed";
  /// The realism preset the errors came from (`ideal`, `typical`, `harsh`; realism.hpp); the
  /// fields themselves are what is simulated.
  std::string realism = "ideal";
  double duration_s = 60.0;  ///< length of the recording when `--duration` is not given, s
  ForestParams forest;
  MotionParams motion;
  LidarParams lidar;
  ImuParams imu;
  GnssParams gnss;
  RigErrorParams rig;
  OutputParams output;
  FaultParams faults;
};

/// The scenarios `taiga simulate --scenario` knows (canonical names).
std::vector<std::string> scenarioNames();
/// The scenario of that name (Scenario::name is then the canonical one); hyphens and underscores
/// are interchangeable (`open_field` = `open-field`, `sparse-pine` = `sparse_pine`).
/// InputError listing the names otherwise.
Scenario scenarioByName(const std::string& name);

}  // namespace taiga::sim
