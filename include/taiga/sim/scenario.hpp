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
};

struct MotionParams {
  double speed_mps = 1.35;             ///< mean walking speed, m/s
  double sensor_height_m = 2.2;        ///< sensor (body) height above the ground, m
  double loop_aspect = 1.0;            ///< loop's y radius / x radius (strip road: thin loop)
  double max_loop_length_m = 300.0;    ///< longer recordings walk the loop again
  double shape_perturbation = 0.18;    ///< relative amplitude of the loop's wiggles
  double speed_variation = 0.25;       ///< relative amplitude of speed changes
  double look_around_deg = 25.0;       ///< slow yaw swings about the walking direction, deg
  double look_around_fast_deg = 10.0;  ///< faster yaw swings, deg
  double step_frequency_hz = 1.8;      ///< gait frequency of the vertical bob, Hz
  double bob_m = 0.025;                ///< vertical bob amplitude, m
  double sway_m = 0.03;                ///< horizontal sway amplitude, m
  double roll_sway_deg = 3.0;          ///< roll oscillation at half the step frequency, deg
  double pitch_sway_deg = 2.5;         ///< pitch oscillation at the step frequency, deg
  double pitch_mean_deg = -3.0;        ///< mean pitch (nose down negative about y), deg
};

struct LidarParams {
  /// Ouster metadata JSON for beam altitude angles and frames; empty or missing: a uniform
  /// spread over `fallback_vertical_fov_deg` with a warning.
  std::string metadata_json = "../shared/data/ouster/OS-0-128-U1_v2.3.0_1024x10.json";
  int beams = 128;            ///< rows; fewer than the metadata's: evenly subsampled
  int columns = 1024;         ///< firings per rotation (512, 1024, 2048)
  double rotation_hz = 10.0;  ///< frames per second
  double fallback_vertical_fov_deg = 90.0;
  double min_range_m = 0.5;     ///< closer returns are suppressed (operator, stick)
  double max_range_m = 45.0;    ///< for a bright target (reflectivity 0.8) at normal incidence
  double range_noise_m = 0.01;  ///< 1-sigma range noise at 0 m
  double range_noise_per_m = 0.0005;  ///< additional 1-sigma noise per metre of range
  double beam_divergence_deg = 0.35;  ///< full angle of the beam footprint
  int sub_rays = 4;                   ///< rays per beam to model the footprint (1 = no divergence)
  double dropout_probability = 0.01;  ///< random missing returns
  bool noise = true;                  ///< false: exact ranges, no dropouts (for tests)
};

struct ImuParams {
  double rate_hz = 200.0;
  /// Continuous-time white-noise densities and bias random walks (a consumer/industrial MEMS
  /// unit such as the ICM-20948 inside Ouster sensors; see docs/simulator.md).
  double accel_noise_density = 2.0e-3;     ///< m/s^2/sqrt(Hz)
  double gyro_noise_density = 2.5e-4;      ///< rad/s/sqrt(Hz)
  double accel_bias_random_walk = 1.0e-4;  ///< m/s^3/sqrt(Hz)
  double gyro_bias_random_walk = 1.0e-5;   ///< rad/s^2/sqrt(Hz)
  double accel_turn_on_bias = 0.05;        ///< 1-sigma bias per axis at start, m/s^2
  double gyro_turn_on_bias = 2.0e-3;       ///< 1-sigma bias per axis at start, rad/s
  double gravity_mps2 = 9.81;
  bool noise = true;  ///< false: exact specific force and angular rate
};

struct GnssParams {
  double rate_hz = 1.0;
  double origin_latitude_deg = 61.0;  ///< geodetic position of the world origin (WGS84)
  double origin_longitude_deg = 24.5;
  double origin_height_m = 120.0;          ///< ellipsoidal height of the world origin, m
  double sigma_open_horizontal_m = 0.4;    ///< 1-sigma error without canopy
  double sigma_canopy_horizontal_m = 2.5;  ///< additional 1-sigma error under full canopy
  double vertical_factor = 1.8;            ///< vertical sigma / horizontal sigma
  double correlation_time_s = 30.0;        ///< first-order Gauss-Markov time constant of the error
  double multipath_probability = 0.03;     ///< per fix under full canopy: start of a multipath jump
  double multipath_jump_m = 15.0;          ///< typical size of a jump, m
  double outage_probability = 0.08;        ///< per fix under full canopy: no fix
  double reported_sigma_factor = 0.7;      ///< reported / true sigma (< 1: optimistic receiver)
  bool noise = true;
};

struct Scenario {
  std::string name = "mixed";
  ForestParams forest;
  MotionParams motion;
  LidarParams lidar;
  ImuParams imu;
  GnssParams gnss;
};

/// The scenarios `taiga simulate --scenario` knows.
std::vector<std::string> scenarioNames();
/// The scenario of that name; InputError listing the names otherwise.
Scenario scenarioByName(const std::string& name);

}  // namespace taiga::sim
