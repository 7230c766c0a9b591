#include "taiga/sim/scenario_yaml.hpp"

#include <fmt/format.h>

#include <array>
#include <limits>
#include <span>
#include <variant>
#include <vector>

#include "taiga/core/config.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/sim/realism.hpp"
#include "taiga/sim/sensor_models.hpp"

namespace taiga::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// One field of a parameter struct: its YAML key, the member, its documentation (unit and
/// meaning) and the range of valid values (numbers only). Adding a field to a struct in
/// scenario.hpp is adding one such line to its table below.
template <class Params>
struct Field {
  std::string_view key;
  std::variant<double Params::*, int Params::*, bool Params::*, std::string Params::*> member;
  std::string_view doc;
  double min = -kInf;
  double max = kInf;
};

/// A ConfigSection (core/config.hpp) over a parameter struct described by a table, so that the
/// io YAML reader and writer handle it like any configuration section.
template <class Params>
class TableSection : public ConfigSection {
 public:
  TableSection(Params& params, std::span<const Field<Params>> fields)
      : params_(params), fields_(fields) {}

  void visit(ConfigVisitor& v) override {
    for (const Field<Params>& f : fields_) {
      std::visit([&](auto member) { v.field(f.key, params_.*member, f.doc); }, f.member);
    }
    visitMore(v);
  }

  void validate() const override {
    for (const Field<Params>& f : fields_) {
      if (const auto* d = std::get_if<double Params::*>(&f.member)) {
        requireInRange(f.key, params_.**d, f.min, f.max, "");
      } else if (const auto* i = std::get_if<int Params::*>(&f.member)) {
        requireInRange(f.key, params_.**i, f.min, f.max, "");
      }
    }
  }

 protected:
  /// Fields that are not plain values (subsections, enumerations).
  virtual void visitMore(ConfigVisitor&) {}
  Params& params_;

 private:
  std::span<const Field<Params>> fields_;
};

// ---- forest -------------------------------------------------------------------------------

const Field<SpeciesMix> kSpeciesFields[] = {
    {"pine", &SpeciesMix::pine, "share of pines (normalized with the others)", 0, 1e6},
    {"spruce", &SpeciesMix::spruce, "share of spruces", 0, 1e6},
    {"birch", &SpeciesMix::birch, "share of birches", 0, 1e6},
};

class SpeciesSection final : public TableSection<SpeciesMix> {
 public:
  explicit SpeciesSection(SpeciesMix& p) : TableSection(p, kSpeciesFields) {}
  void validate() const override {
    TableSection::validate();
    if (params_.pine + params_.spruce + params_.birch <= 0.0) {
      throw ConfigError("pine", "expected at least one share > 0 (pine, spruce, birch)");
    }
  }
};

const Field<ForestParams> kForestFields[] = {
    {"stems_per_ha", &ForestParams::stems_per_ha, "mature trees (DBH >= 8 cm) per hectare", 0, 3000},
    {"dbh_mean_m", &ForestParams::dbh_mean_m, "mean diameter at breast height, m", 0.08, 0.5},
    {"dbh_sigma_m", &ForestParams::dbh_sigma_m, "spread of DBH, m", 0, 0.3},
    {"saplings_per_ha", &ForestParams::saplings_per_ha, "young trees 0.5-4 m tall per ha", 0, 10000},
    {"shrubs_per_ha", &ForestParams::shrubs_per_ha, "low clumps of foliage per ha", 0, 10000},
    {"boulders_per_ha", &ForestParams::boulders_per_ha, "rocks 0.3-1.5 m across per ha", 0, 1000},
    {"logs_per_ha", &ForestParams::logs_per_ha, "fallen stems per ha", 0, 1000},
    {"terrain_slope", &ForestParams::terrain_slope, "mean terrain gradient, m per m", 0, 0.5},
    {"terrain_undulation_m", &ForestParams::terrain_undulation_m, "long-wave relief amplitude, m", 0, 10},
    {"micro_relief_m", &ForestParams::micro_relief_m, "hummock amplitude, m", 0, 1},
    {"road_half_width_m", &ForestParams::road_half_width_m, "> 0: a strip road along world x, m", 0, 10},
    {"path_clearance_m", &ForestParams::path_clearance_m, "no stem closer to the path, m", 0, 10},
    {"wind_sway_m", &ForestParams::wind_sway_m, "sway amplitude 20 m above ground (0: still), m", 0, 2},
    {"wind_period_s", &ForestParams::wind_period_s, "period of the sway, s", 0.5, 60},
};

class ForestSection final : public TableSection<ForestParams> {
 public:
  explicit ForestSection(ForestParams& p) : TableSection(p, kForestFields), species_(p.species) {}

 private:
  void visitMore(ConfigVisitor& v) override {
    v.section("species", species_, "shares of the tree species");
  }
  SpeciesSection species_;
};

// ---- motion (ranges: MotionParams::validate) -------------------------------------------------

const Field<MotionParams> kMotionFields[] = {
    {"speed_mps", &MotionParams::speed_mps, "mean walking speed, m/s"},
    {"sensor_height_m", &MotionParams::sensor_height_m, "sensor (body) height above ground, m"},
    {"loop_aspect", &MotionParams::loop_aspect, "loop's y radius / x radius"},
    {"loop_straightness", &MotionParams::loop_straightness,
     "0: an elliptic loop; k > 0: straight sides, ends of radius about Ry"},
    {"max_loop_length_m", &MotionParams::max_loop_length_m, "longer recordings repeat the loop, m"},
    {"shape_perturbation", &MotionParams::shape_perturbation, "relative loop wiggles"},
    {"loop_lobes", &MotionParams::loop_lobes, "1: one loop; 3, 4, 5: a cloverleaf"},
    {"lobe_size_variation", &MotionParams::lobe_size_variation, "relative lobe size difference"},
    {"speed_variation", &MotionParams::speed_variation, "relative amplitude of speed changes"},
    {"look_around_deg", &MotionParams::look_around_deg, "slow yaw swings, deg"},
    {"look_around_fast_deg", &MotionParams::look_around_fast_deg, "faster yaw swings, deg"},
    {"step_frequency_hz", &MotionParams::step_frequency_hz, "gait frequency, Hz"},
    {"bob_m", &MotionParams::bob_m, "vertical bob amplitude, m"},
    {"sway_m", &MotionParams::sway_m, "horizontal sway amplitude, m"},
    {"roll_sway_deg", &MotionParams::roll_sway_deg, "roll oscillation, deg"},
    {"pitch_sway_deg", &MotionParams::pitch_sway_deg, "pitch oscillation, deg"},
    {"pitch_mean_deg", &MotionParams::pitch_mean_deg, "mean pitch (nose down < 0), deg"},
    {"pause_interval_s", &MotionParams::pause_interval_s, "mean walk between pauses, s (0: none)"},
    {"pause_min_s", &MotionParams::pause_min_s, "shortest pause, s"},
    {"pause_max_s", &MotionParams::pause_max_s, "longest pause, s"},
    {"pause_ramp_s", &MotionParams::pause_ramp_s, "time to stop and to start again, s"},
    {"fast_turn_interval_s", &MotionParams::fast_turn_interval_s, "mean time between fast turns, s (0: none)"},
    {"fast_turn_min_deg", &MotionParams::fast_turn_min_deg, "smallest fast turn, deg"},
    {"fast_turn_max_deg", &MotionParams::fast_turn_max_deg, "largest fast turn, deg"},
    {"fast_turn_rate_deg_s", &MotionParams::fast_turn_rate_deg_s, "peak yaw rate of a turn, deg/s"},
    {"harvester_speed_min_mps", &MotionParams::harvester_speed_min_mps, "slowest drive, m/s"},
    {"harvester_speed_max_mps", &MotionParams::harvester_speed_max_mps, "fastest drive, m/s"},
    {"harvester_drive_min_m", &MotionParams::harvester_drive_min_m, "shortest drive between stops, m"},
    {"harvester_drive_max_m", &MotionParams::harvester_drive_max_m, "longest drive between stops, m"},
    {"harvester_stop_min_s", &MotionParams::harvester_stop_min_s, "shortest tree stop, s"},
    {"harvester_stop_max_s", &MotionParams::harvester_stop_max_s, "longest tree stop, s"},
    {"harvester_ramp_s", &MotionParams::harvester_ramp_s, "time to speed up or slow down, s"},
    {"harvester_reverse_probability", &MotionParams::harvester_reverse_probability, "after a stop: back up first"},
    {"harvester_reverse_max_m", &MotionParams::harvester_reverse_max_m, "longest reversing, m"},
    {"harvester_lateral_m", &MotionParams::harvester_lateral_m, "side-to-side weave amplitude, m"},
    {"harvester_vibration_mps2", &MotionParams::harvester_vibration_mps2, "vibration peak acceleration, m/s^2"},
    {"harvester_vibration_rate_deg_s", &MotionParams::harvester_vibration_rate_deg_s, "vibration peak angular rate, deg/s"},
    {"harvester_vibration_min_hz", &MotionParams::harvester_vibration_min_hz, "lowest vibration frequency, Hz"},
    {"harvester_vibration_max_hz", &MotionParams::harvester_vibration_max_hz, "highest vibration frequency, Hz"},
};

constexpr std::array<std::pair<std::string_view, MotionModel>, 2> kMotionModels = {{
    {"handheld", MotionModel::kHandheld},
    {"harvester", MotionModel::kHarvester},
}};

class MotionSection final : public TableSection<MotionParams> {
 public:
  explicit MotionSection(MotionParams& p) : TableSection(p, kMotionFields) {}

 private:
  void visitMore(ConfigVisitor& v) override {
    enumField(v, "model", params_.model, kMotionModels, "which rig moves");
  }
};

// ---- sensors --------------------------------------------------------------------------------

const Field<LidarParams> kLidarFields[] = {
    {"metadata_json", &LidarParams::metadata_json, "Ouster metadata JSON instead of the model (empty: the model)"},
    {"beams", &LidarParams::beams, "rows, subsampled from the beam table (0: all)", 0, 128},
    {"columns", &LidarParams::columns, "firings per rotation", 16, 4096},
    {"rotation_hz", &LidarParams::rotation_hz, "frames per second", 1, 40},
    {"min_range_m", &LidarParams::min_range_m, "closer returns are suppressed, m", 0, 10},
    {"max_range_m", &LidarParams::max_range_m, "for reflectivity 0.8 at normal incidence, m", 1, 500},
    {"range_noise_m", &LidarParams::range_noise_m, "1-sigma range noise at 0 m, m", 0, 1},
    {"range_noise_per_m", &LidarParams::range_noise_per_m, "added 1-sigma noise per m of range", 0, 0.1},
    {"beam_divergence_deg", &LidarParams::beam_divergence_deg, "full angle of the footprint, deg", 0, 5},
    {"sub_rays", &LidarParams::sub_rays, "rays per beam at depth edges (1: no divergence)", 1, 8},
    {"dropout_probability", &LidarParams::dropout_probability, "random missing returns", 0, 1},
    {"range_noise_at_limit_m", &LidarParams::range_noise_at_limit_m, "added 1-sigma noise at the detection limit, m", 0, 1},
    {"packet_loss_probability", &LidarParams::packet_loss_probability, "share of lost 16-column packets", 0, 1},
    {"noise", &LidarParams::noise, "false: exact ranges, no dropouts"},
};

class LidarSection final : public TableSection<LidarParams> {
 public:
  explicit LidarSection(LidarParams& p) : TableSection(p, kLidarFields) {}

 private:
  void visitMore(ConfigVisitor& v) override {
    const std::vector<std::string> names = sensorModelNames();
    const std::vector<std::string_view> allowed(names.begin(), names.end());
    v.choice("model", params_.model, allowed, "built-in beam table and frames");
  }
};

const Field<ImuParams> kImuFields[] = {
    {"rate_hz", &ImuParams::rate_hz, "samples per second", 1, 10000},
    {"accel_noise_density", &ImuParams::accel_noise_density, "m/s^2/sqrt(Hz)", 0, 1},
    {"gyro_noise_density", &ImuParams::gyro_noise_density, "rad/s/sqrt(Hz)", 0, 1},
    {"accel_bias_random_walk", &ImuParams::accel_bias_random_walk, "m/s^3/sqrt(Hz)", 0, 1},
    {"gyro_bias_random_walk", &ImuParams::gyro_bias_random_walk, "rad/s^2/sqrt(Hz)", 0, 1},
    {"accel_turn_on_bias", &ImuParams::accel_turn_on_bias, "1-sigma per axis, m/s^2", 0, 5},
    {"gyro_turn_on_bias", &ImuParams::gyro_turn_on_bias, "1-sigma per axis, rad/s", 0, 1},
    {"gravity_mps2", &ImuParams::gravity_mps2, "m/s^2", 9, 10.5},
    {"noise_density_factor", &ImuParams::noise_density_factor, "true / stated noise densities", 0, 100},
    {"bias_walk_factor", &ImuParams::bias_walk_factor, "true / stated bias random walks", 0, 100},
    {"accel_bias_instability_mps2", &ImuParams::accel_bias_instability_mps2, "1-sigma Gauss-Markov bias, m/s^2", 0, 1},
    {"gyro_bias_instability_radps", &ImuParams::gyro_bias_instability_radps, "1-sigma Gauss-Markov bias, rad/s", 0, 0.1},
    {"bias_correlation_s", &ImuParams::bias_correlation_s, "Gauss-Markov time of the biases, s", 0.1, 1e6},
    {"scale_factor_error", &ImuParams::scale_factor_error, "1-sigma per-axis scale error (0.01 = 1 %)", 0, 0.2},
    {"misalignment_deg", &ImuParams::misalignment_deg, "1-sigma axis non-orthogonality, deg", 0, 10},
    {"gyro_g_sensitivity_deg_s_per_g", &ImuParams::gyro_g_sensitivity_deg_s_per_g, "1-sigma gyro error per g, deg/s/g", 0, 10},
    {"accel_range_g", &ImuParams::accel_range_g, "clipping of the accelerometer (0: none), g", 0, 100},
    {"gyro_range_deg_s", &ImuParams::gyro_range_deg_s, "clipping of the gyroscope (0: none), deg/s", 0, 10000},
    {"timestamp_jitter_s", &ImuParams::timestamp_jitter_s, "1-sigma error of each stamp, s", 0, 0.1},
    {"noise", &ImuParams::noise, "false: exact specific force and angular rate"},
    {"orientation_output", &ImuParams::orientation_output, "samples carry an AHRS orientation"},
    {"orientation_tilt_error_deg", &ImuParams::orientation_tilt_error_deg, "1-sigma roll/pitch error, deg", 0, 30},
    {"orientation_tilt_correlation_s", &ImuParams::orientation_tilt_correlation_s, "Gauss-Markov time, s", 0.01, 1e6},
    {"orientation_heading_walk_deg_per_sqrt_s", &ImuParams::orientation_heading_walk_deg_per_sqrt_s, "heading random walk, deg/sqrt(s)", 0, 10},
    {"orientation_heading_offset_deg", &ImuParams::orientation_heading_offset_deg, "constant heading error, deg", -360, 360},
};

const Field<GnssParams> kGnssFields[] = {
    {"rate_hz", &GnssParams::rate_hz, "fixes per second", 0.01, 100},
    {"origin_latitude_deg", &GnssParams::origin_latitude_deg, "world origin, WGS84 latitude, deg", -85, 85},
    {"origin_longitude_deg", &GnssParams::origin_longitude_deg, "world origin, longitude, deg", -180, 180},
    {"origin_height_m", &GnssParams::origin_height_m, "world origin, ellipsoidal height, m", -500, 9000},
    {"world_yaw_deg", &GnssParams::world_yaw_deg, "angle from east to world x, ccw, deg", -360, 360},
    {"georef_epsg", &GnssParams::georef_epsg, "projected CRS of georef_truth.yaml", 1024, 999999},
    {"sigma_open_horizontal_m", &GnssParams::sigma_open_horizontal_m, "1-sigma error in the open, m", 0, 100},
    {"sigma_canopy_horizontal_m", &GnssParams::sigma_canopy_horizontal_m, "added under full canopy, m", 0, 100},
    {"vertical_factor", &GnssParams::vertical_factor, "vertical / horizontal sigma", 0, 10},
    {"correlation_time_s", &GnssParams::correlation_time_s, "Gauss-Markov time of the error, s", 0.01, 1e6},
    {"multipath_probability", &GnssParams::multipath_probability, "per fix under full canopy", 0, 1},
    {"multipath_jump_m", &GnssParams::multipath_jump_m, "typical jump, m", 0, 1000},
    {"outage_probability", &GnssParams::outage_probability, "per fix under full canopy", 0, 1},
    {"reported_sigma_factor", &GnssParams::reported_sigma_factor, "reported / true sigma", 0.01, 100},
    {"reported_sigma_noise", &GnssParams::reported_sigma_noise, "log-normal spread of the reported sigma per fix", 0, 2},
    {"noise", &GnssParams::noise, "false: exact positions, no outages"},
};

const Field<RigErrorParams> kRigFields[] = {
    {"extrinsic_rotation_error_deg", &RigErrorParams::extrinsic_rotation_error_deg, "true vs stated T_body_lidar, deg", 0, 180},
    {"extrinsic_translation_error_m", &RigErrorParams::extrinsic_translation_error_m, "true vs stated lever arm, m", 0, 10},
    {"lidar_time_offset_s", &RigErrorParams::lidar_time_offset_s, "true rig.lidar_time_offset_s, s", -1, 1},
    {"lidar_clock_drift_ppm", &RigErrorParams::lidar_clock_drift_ppm, "lidar clock rate error, ppm", -1000, 1000},
};

const Field<FaultParams> kFaultFields[] = {
    {"imu_gap_start_s", &FaultParams::imu_gap_start_s, "no IMU samples from here, s", 0, 86400},
    {"imu_gap_s", &FaultParams::imu_gap_s, "for this long (0: no gap), s", 0, 86400},
    {"packet_burst_start_s", &FaultParams::packet_burst_start_s, "scans from here lose packets, s", 0, 86400},
    {"packet_burst_scans", &FaultParams::packet_burst_scans, "this many scans (0: none)", 0, 1000000},
    {"packet_burst_loss", &FaultParams::packet_burst_loss, "share of their 16-column packets lost", 0, 1},
    {"splice_at_s", &FaultParams::splice_at_s, "the scan starting here is replaced (0: none), s", 0, 86400},
    {"splice_from_s", &FaultParams::splice_from_s, "by the scan simulated at this time, s", 0, 86400},
    {"open_field_start_s", &FaultParams::open_field_start_s, "scans starting here see only the ground, s", 0, 86400},
    {"open_field_s", &FaultParams::open_field_s, "for this long (0: none), s", 0, 86400},
};

const Field<OutputParams> kOutputFields[] = {
    {"scan_stride", &OutputParams::scan_stride, "keep every n-th scan", 1, 1000},
    {"imu", &OutputParams::imu, "write the IMU topic"},
    {"gnss", &OutputParams::gnss, "write the GNSS topic"},
};

class OutputSection final : public TableSection<OutputParams> {
 public:
  explicit OutputSection(OutputParams& p) : TableSection(p, kOutputFields) {}

 private:
  void visitMore(ConfigVisitor& v) override {
    static constexpr std::string_view kLayouts[] = {"ouster", "velodyne", "deskewed", "untimed"};
    v.choice("point_layout", params_.point_layout, kLayouts,
             "ouster (organized, t), velodyne (flat, ring, time), deskewed (flat, no time), "
             "untimed (flat, no time, a raw sweep)");
    static constexpr std::string_view kProfiles[] = {"", "LEGACY", "RNG19_RFL8_SIG16_NIR16",
                                                     "RNG15_RFL8_NIR8"};
    v.choice("pcap_profile", params_.pcap_profile, kProfiles,
             "also capture.pcap + capture.json in this Ouster lidar profile; empty: none");
  }
};

const Field<Scenario> kScenarioFields[] = {
    {"duration_s", &Scenario::duration_s, "recording length without --duration, s", 0.1, 86400},
};

class ScenarioSection final : public TableSection<Scenario> {
 public:
  explicit ScenarioSection(Scenario& s)
      : TableSection(s, kScenarioFields),
        forest_(s.forest),
        motion_(s.motion),
        lidar_(s.lidar),
        imu_(s.imu, kImuFields),
        gnss_(s.gnss, kGnssFields),
        rig_(s.rig, kRigFields),
        output_(s.output),
        faults_(s.faults, kFaultFields) {}

 private:
  void visit(ConfigVisitor& v) override {
    const std::vector<std::string> names = scenarioNames();
    const std::vector<std::string_view> allowed(names.begin(), names.end());
    v.choice("name", params_.name, allowed, "the scenario this file describes");
    const std::vector<std::string> presets = realismNames();
    const std::vector<std::string_view> realism(presets.begin(), presets.end());
    v.choice("realism", params_.realism, realism,
             "the preset the error fields came from (the fields are what is simulated)");
    TableSection::visit(v);
  }
  void visitMore(ConfigVisitor& v) override {
    v.section("forest", forest_, "the generated stand and terrain");
    v.section("motion", motion_, "how the rig moves");
    v.section("lidar", lidar_, "the lidar");
    v.section("imu", imu_, "the IMU");
    v.section("gnss", gnss_, "the GNSS receiver and the world frame's georeference");
    v.section("rig", rig_, "how the true rig differs from its rig.yaml");
    v.section("output", output_, "what the recording holds");
    v.section("faults", faults_, "faults injected into the recording (all off by default)");
  }
  ForestSection forest_;
  MotionSection motion_;
  LidarSection lidar_;
  TableSection<ImuParams> imu_;
  TableSection<GnssParams> gnss_;
  TableSection<RigErrorParams> rig_;
  OutputSection output_;
  TableSection<FaultParams> faults_;
};

}  // namespace

void applyScenarioOverridesText(std::string_view text, std::string_view source_name,
                                Scenario& scenario) {
  ScenarioSection section(scenario);
  io::readConfigYamlText(text, source_name, section);
  try {
    scenario.motion.validate();  // the motion model's own ranges (messages name motion.<field>)
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", source_name, e.what()));
  }
}

void applyScenarioOverrides(const std::filesystem::path& path, Scenario& scenario) {
  ScenarioSection section(scenario);
  io::readConfigYaml(path, section);
  try {
    scenario.motion.validate();
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

std::string scenarioYaml(const Scenario& scenario) {
  Scenario copy = scenario;  // the visitor interface takes mutable references
  ScenarioSection section(copy);
  return io::writeConfigYaml(section);
}

}  // namespace taiga::sim
