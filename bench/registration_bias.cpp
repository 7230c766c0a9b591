// Why is the odometry's trajectory about 0.2 % too small? This program takes the deskew, the IMU
// and the smoother out of the question: every scan of a simulated recording is deskewed with the
// *true* trajectory, and registration alone is measured (docs/odometry.md, "Scale").
//
//   registration_bias SIM                  each scan registered, from its true pose, to a map of
//                                          the keyframes behind it at their true poses: the mean
//                                          error along the direction of travel is the bias
//   registration_bias SIM --odometry       a bare lidar-only odometry (map from its own
//                                          estimates): its Sim(3) scale and path length ratio
//                                          against the truth
//   registration_bias SIM --scene-check    are the deskewed points and groundtruth.tum exact?
//
// SIM is a `taiga simulate` output directory. Keyframes every metre, source points in 0.4 m
// voxels and map points in 0.2 m voxels per keyframe, as the odometry's defaults.
#include <CLI/CLI.hpp>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "taiga/core/angles.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/eval/drift.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/recording.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/preprocess/crop.hpp"
#include "taiga/preprocess/deskew.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/gicp.hpp"
#include "taiga/registration/ndt.hpp"
#include "taiga/sim/scenario_yaml.hpp"
#include "taiga/sim/simulator.hpp"
#include "taiga/trees/tree_files.hpp"

using namespace taiga;

namespace {

struct Options {
  std::string sim_dir;
  std::string method = "ndt";  ///< ndt | d2d | gicp
  double resolution_m = 1.0;
  double coarse_resolution_m = 0.0;  ///< --odometry: a first NDT pass (0: none)
  int num_keyframes = 20;
  int skip_keyframes = 0;  ///< leave out the keyframes nearest the scan
  bool map_ahead = false;  ///< map from the keyframes after the scan
  int every = 5;           ///< register every k-th scan
  // Which map points: seen from their keyframe within this angle of the scan's view of them.
  double max_view_angle_deg = 180.0;
  bool view_from_keyframe = false;  ///< --odometry: the angle from the latest keyframe instead
  // Which source points (body frame).
  double source_min_z_m = -1e9, source_max_z_m = 1e9;
  double source_min_range_m = 0.0, source_max_range_m = 1e9;
  // Diagnoses.
  double range_scale = 1.0;     ///< every range multiplied by this
  double range_offset_m = 0.0;  ///< and this added
  bool world_voxels = false;    ///< voxel grids fixed in the world (true pose), not the body
  /// Each voxel's point: centroid, measured (the return nearest the centroid) or raw (no voxels).
  std::string source_sample = "centroid", map_sample = "centroid";
  double source_noise_m = 0.0, map_noise_m = 0.0;  ///< added 1-sigma range noise (diagnosis)
  /// > 0: the map's stem cells know this range noise (sigma_m + per_m x range) along the beams.
  double beam_sigma_m = 0.0, beam_sigma_per_m = 0.0;
  bool reverse = false;  ///< also register the map (as source) to the scan (as target)
  bool stem_cells = false;  ///< NdtConfig::stem_cells
  bool stem_cells_across_borders = false;  ///< NdtConfig::stem_cells_across_borders
  /// Diagnosis: the map points from this recording instead (the same simulation with other
  /// lidar settings, e.g. without noise: what a noise-free map would give).
  std::string map_from;
};

struct TrueScan {
  lie::SE3 T_world_body;                        ///< truth at the scan's end
  std::vector<Eigen::Vector3d> source_in_body;  ///< 0.4 m voxels, as the odometry registers
  std::vector<Eigen::Vector3d> map_in_body;     ///< 0.2 m voxels, as keyframes enter the map
};

std::vector<Eigen::Vector3d> representatives(const PointCloud& cloud, double voxel_m,
                                             const std::string& mode,
                                             const Eigen::Vector3d& sensor) {
  if (mode == "raw") return cloud.positions;
  return preprocess::voxelFilter(cloud, voxel_m, preprocess::voxelRepresentative(mode), sensor)
      .positions;
}

std::vector<Eigen::Vector3d> voxelCentroids(const PointCloud& cloud_in_body, double voxel_m,
                                            const lie::SE3& T_world_body, bool world_grid,
                                            const std::string& mode,
                                            const Eigen::Vector3d& lidar_in_body) {
  if (!world_grid) return representatives(cloud_in_body, voxel_m, mode, lidar_in_body);
  PointCloud in_world;
  for (const Eigen::Vector3d& p : cloud_in_body.positions) in_world.positions.push_back(T_world_body * p);
  std::vector<Eigen::Vector3d> centroids =
      representatives(in_world, voxel_m, mode, T_world_body * lidar_in_body);
  const lie::SE3 T_body_world = T_world_body.inverse();
  for (Eigen::Vector3d& p : centroids) p = T_body_world * p;
  return centroids;
}

std::vector<TrueScan> readTrueScans(const Options& o, const SystemConfig& config,
                                    const Trajectory& truth) {
  io::Recording recording =
      io::openRecording(o.sim_dir + "/recording.bag", config.recording, config.rig);
  std::vector<TrueScan> scans;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  while (auto event = recording.next()) {
    const auto* scan = std::get_if<io::Scan>(&*event);
    if (scan == nullptr || !truth.covers(scan->t_start_s) || !truth.covers(scan->t_end_s)) continue;
    PointCloud in_lidar = preprocess::keepRange(scan->cloud_in_lidar, 1.0, 80.0);
    for (Eigen::Vector3d& p : in_lidar.positions) p *= o.range_scale + o.range_offset_m / p.norm();
    const auto inBody = [&](double noise_m) {
      PointCloud noisy = in_lidar;
      for (Eigen::Vector3d& p : noisy.positions) p += noise_m * normal(rng) * p.normalized();
      return preprocess::deskew(noisy, config.rig.T_body_lidar, truth, scan->t_end_s)
          .cloud_in_body;
    };
    const lie::SE3 T_world_body = truth.poseAt(scan->t_end_s);
    scans.push_back({T_world_body,
                     voxelCentroids(inBody(o.source_noise_m), 0.4, T_world_body, o.world_voxels,
                                    o.source_sample, config.rig.T_body_lidar.translation()),
                     voxelCentroids(inBody(o.map_noise_m), 0.2, T_world_body, o.world_voxels,
                                    o.map_sample, config.rig.T_body_lidar.translation())});
  }
  return scans;
}

/// The keyframes' map points in the world, those seen within max_view_angle_deg of the view from
/// `viewpoint_world`.
std::vector<Eigen::Vector3d> mapInWorld(const std::vector<TrueScan>& scans,
                                        const std::vector<std::size_t>& keyframes,
                                        const std::vector<lie::SE3>& T_world_keyframe,
                                        const Eigen::Vector3d& viewpoint_world,
                                        double max_view_angle_deg,
                                        std::vector<Eigen::Vector3d>* sensors = nullptr) {
  const double min_cos = std::cos(max_view_angle_deg * kRadPerDeg);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t j = 0; j < keyframes.size(); ++j) {
    const lie::SE3& T = T_world_keyframe[j];
    for (const Eigen::Vector3d& p : scans[keyframes[j]].map_in_body) {
      const Eigen::Vector3d q = T * p;
      if (max_view_angle_deg < 180.0 &&
          (q - T.translation()).normalized().dot((q - viewpoint_world).normalized()) < min_cos)
        continue;
      points.push_back(q);
      if (sensors != nullptr) sensors->push_back(T.translation());
    }
  }
  return points;
}

/// The map's statistics at the fine resolution; with --beam-noise and the points' sensors, the
/// stem cells' noise shares too (VoxelStatistics::add with BeamNoise; the body origin stands for
/// the lidar's).
registration::VoxelStatistics fineStatistics(const Options& o,
                                             const std::vector<Eigen::Vector3d>& map,
                                             const std::vector<Eigen::Vector3d>* sensors,
                                             bool circle_moments) {
  registration::VoxelStatistics statistics(o.resolution_m, circle_moments);
  if (sensors == nullptr) {
    statistics.add(map);
    return statistics;
  }
  for (std::size_t begin = 0; begin < map.size();) {
    std::size_t end = begin;
    while (end < map.size() && (*sensors)[end] == (*sensors)[begin]) ++end;
    statistics.add(std::span(map).subspan(begin, end - begin),
                   {(*sensors)[begin], o.beam_sigma_m, o.beam_sigma_per_m});
    begin = end;
  }
  return statistics;
}

registration::NdtTarget fineTarget(const Options& o, const std::vector<Eigen::Vector3d>& map,
                                   const std::vector<Eigen::Vector3d>* sensors,
                                   const registration::NdtConfig& ndt) {
  return registration::NdtTarget(fineStatistics(o, map, sensors, ndt.stem_cells), ndt);
}

registration::RegistrationResult align(const Options& o, std::span<const Eigen::Vector3d> source,
                                       const std::vector<Eigen::Vector3d>& map_in_world,
                                       const lie::SE3& guess,
                                       const std::vector<Eigen::Vector3d>* sensors = nullptr) {
  registration::NdtConfig ndt;
  ndt.resolution_m = o.resolution_m;
  ndt.stem_cells = o.stem_cells;
  ndt.stem_cells_across_borders = o.stem_cells_across_borders;
  if (o.method == "gicp") return registration::alignGicp(source, map_in_world, guess, {});
  lie::SE3 start = guess;
  if (o.coarse_resolution_m > 0.0) {
    start = registration::alignNdt(
                source,
                registration::NdtTarget::fromPoints(map_in_world, o.coarse_resolution_m,
                                                    ndt.cellsAt(o.coarse_resolution_m)),
                guess, ndt)
                .T_target_source;
  }
  const auto target = fineTarget(o, map_in_world, sensors, ndt);
  return o.method == "d2d" ? registration::alignD2dNdt(source, target, start, ndt)
                           : registration::alignNdt(source, target, start, ndt);
}

double mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

/// Direction of travel at scan i, horizontal: from the previous scan's true position to the next
/// one's; zero when standing still.
Eigen::Vector3d forwardOf(const std::vector<TrueScan>& scans, std::size_t i) {
  Eigen::Vector3d forward =
      scans[i + 1].T_world_body.translation() - scans[i - 1].T_world_body.translation();
  forward.z() = 0.0;
  return forward.norm() < 0.05 ? Eigen::Vector3d::Zero() : forward.normalized();
}

/// Each scan from its true pose against a map of true keyframe poses: the error's mean along the
/// direction of travel, across it and up.
void measureBias(const Options& o, const std::vector<TrueScan>& scans) {
  std::vector<std::size_t> keyframes{0};  // every metre of true path
  for (std::size_t i = 1; i < scans.size(); ++i) {
    const Eigen::Vector3d last = scans[keyframes.back()].T_world_body.translation();
    if ((scans[i].T_world_body.translation() - last).norm() >= 1.0) keyframes.push_back(i);
  }
  std::vector<double> along_m, across_m, up_m, reverse_along_m;
  for (std::size_t i = 1; i + 1 < scans.size(); i += o.every) {
    std::vector<std::size_t> chosen;
    for (std::size_t k : keyframes)
      if (o.map_ahead ? k > i : k < i) chosen.push_back(k);
    const auto needed = static_cast<std::size_t>(o.num_keyframes + o.skip_keyframes);
    if (chosen.size() < needed) continue;
    if (o.map_ahead) chosen.resize(needed);
    else chosen.erase(chosen.begin(), chosen.end() - needed);
    // Drop the nearest skip_keyframes.
    if (o.map_ahead) chosen.erase(chosen.begin(), chosen.begin() + o.skip_keyframes);
    else chosen.resize(o.num_keyframes);
    std::vector<lie::SE3> T_world_keyframe;
    for (std::size_t k : chosen) T_world_keyframe.push_back(scans[k].T_world_body);
    const TrueScan& scan = scans[i];
    std::vector<Eigen::Vector3d> source;
    for (const Eigen::Vector3d& p : scan.source_in_body)
      if (p.z() >= o.source_min_z_m && p.z() <= o.source_max_z_m &&
          p.norm() >= o.source_min_range_m && p.norm() <= o.source_max_range_m)
        source.push_back(p);
    const std::vector<Eigen::Vector3d> map_in_world =
        mapInWorld(scans, chosen, T_world_keyframe, scan.T_world_body.translation(),
                   o.max_view_angle_deg);
    auto result = align(o, source, map_in_world, scan.T_world_body);
    if (!result.converged) continue;
    if (o.reverse) {
      // The map, thinned to the source's 0.4 m, as the source; the scan's map points as target.
      PointCloud map_cloud;
      map_cloud.positions = map_in_world;
      const auto reverse =
          align(o, preprocess::voxelFilter(map_cloud, 0.4).positions, scan.map_in_body,
                scan.T_world_body.inverse());
      if (!reverse.converged) continue;
      reverse_along_m.push_back((reverse.T_target_source.inverse().translation() -
                                 scan.T_world_body.translation())
                                    .dot(forwardOf(scans, i)));
    }
    const Eigen::Vector3d forward = forwardOf(scans, i);
    if (forward.isZero()) continue;  // standing still
    const Eigen::Vector3d error_world =
        result.T_target_source.translation() - scan.T_world_body.translation();
    along_m.push_back(error_world.dot(forward));
    across_m.push_back(error_world.dot(Eigen::Vector3d::UnitZ().cross(forward)));
    up_m.push_back(error_world.z());
  }
  std::printf("%s, map of %d keyframes %s the scan (%d nearest left out), %.2f m cells: %zu scans; "
              "error along travel %+.2f mm, left %+.2f mm, up %+.2f mm\n",
              o.method.c_str(), o.num_keyframes, o.map_ahead ? "ahead of" : "behind",
              o.skip_keyframes, o.resolution_m, along_m.size(), 1e3 * mean(along_m),
              1e3 * mean(across_m), 1e3 * mean(up_m));
  if (o.reverse)
    std::printf("map registered to the scan: error along travel %+.2f mm\n",
                1e3 * mean(reverse_along_m));
}

/// The simulator's stems (trees.csv): the axis at breast height, its lean and the radius there.
struct TrueStem {
  Eigen::Vector3d at_breast_height;
  Eigen::Vector2d lean_per_m;  ///< horizontal drift of the axis per m of height
  double radius_m;
};

std::vector<TrueStem> readTrueStems(const std::string& path) {
  constexpr double kBreastHeight_m = 1.3;  // x_bh_m, y_bh_m are the axis there
  std::vector<TrueStem> stems;
  for (const trees::TreeRecord& t : trees::readTreesCsv(path)) {
    const double lean = std::tan(t.lean_deg * kRadPerDeg);
    const double azimuth = t.lean_azimuth_deg * kRadPerDeg;
    stems.push_back({Eigen::Vector3d(t.bh_xy_m.x(), t.bh_xy_m.y(), t.ground_z_m + kBreastHeight_m),
                     lean * Eigen::Vector2d(std::cos(azimuth), std::sin(azimuth)), 0.5 * t.dbh_m});
  }
  return stems;
}

/// Horizontal distance from q to the nearest true stem's surface (negative inside), m.
double distanceToStem(const std::vector<TrueStem>& stems, const Eigen::Vector3d& q) {
  double best = 1e9;
  for (const TrueStem& s : stems) {
    const Eigen::Vector2d axis =
        s.at_breast_height.head<2>() + s.lean_per_m * (q.z() - s.at_breast_height.z());
    best = std::min(best, (q.head<2>() - axis).norm() - s.radius_m);
  }
  return best;
}

/// Where the bias comes from: each scan's NDT gradient at its true pose, split by the kind of
/// surface each source point is scored against (its cell's normal: ground-like, upright or
/// other) and by range, mapped through the whole scan's Hessian to the pose error each class
/// alone would cause (delta = -H^-1 g, body frame, then along travel). The classes add up to the
/// one-Newton-step error from the truth.
void measureForces(const Options& o, const std::vector<TrueScan>& scans) {
  const std::vector<TrueStem> stems = readTrueStems(o.sim_dir + "/trees.csv");
  std::vector<std::size_t> keyframes{0};
  for (std::size_t i = 1; i < scans.size(); ++i) {
    const Eigen::Vector3d last = scans[keyframes.back()].T_world_body.translation();
    if ((scans[i].T_world_body.translation() - last).norm() >= 1.0) keyframes.push_back(i);
  }
  const char* kClasses[] = {"ground (|n_z| > 0.8)", "upright (|n_z| < 0.3)", "other", "range < 5 m",
                            "range 5-10 m", "range 10-20 m", "range > 20 m", "in stem cells",
                            "upright, other, stem", "upright, other, no stem",
                            // upright, other, stem by the stem gate their cell fails
                            "  (passes)", "  few points", "  leaning or flat", "  no circle",
                            "  radius", "  residual", "  short arc"};
  constexpr int kNumClasses = 17;
  std::vector<double> along_m[kNumClasses], up_m[kNumClasses], total_along_m, total_up_m;
  registration::NdtConfig ndt;
  ndt.resolution_m = o.resolution_m;
  ndt.stem_cells = o.stem_cells;
  ndt.stem_cells_across_borders = o.stem_cells_across_borders;
  std::size_t num_points = 0, num_upright = 0, num_stem = 0;
  std::size_t gate_counts[7] = {0, 0, 0, 0, 0, 0, 0};
  for (std::size_t i = 1; i + 1 < scans.size(); i += o.every) {
    std::vector<std::size_t> chosen;
    for (std::size_t k : keyframes)
      if (k < i) chosen.push_back(k);
    if (chosen.size() < static_cast<std::size_t>(o.num_keyframes)) continue;
    chosen.erase(chosen.begin(), chosen.end() - o.num_keyframes);
    std::vector<lie::SE3> T_world_keyframe;
    for (std::size_t k : chosen) T_world_keyframe.push_back(scans[k].T_world_body);
    const TrueScan& scan = scans[i];
    const Eigen::Vector3d forward = forwardOf(scans, i);
    if (forward.isZero()) continue;
    std::vector<Eigen::Vector3d> sensors;
    const std::vector<Eigen::Vector3d> map_points = mapInWorld(
        scans, chosen, T_world_keyframe, scan.T_world_body.translation(), 180.0, &sensors);
    // The statistics with circle moments whatever --stem-cells: which stem gate the cells of
    // near-stem points outside stem cells fail.
    const registration::VoxelStatistics statistics =
        fineStatistics(o, map_points, &sensors, true);
    const registration::NdtTarget target(statistics, ndt);
    std::unordered_map<registration::VoxelKey, registration::CellMoments> moments_of;
    for (const registration::CellMoments& m : statistics.moments()) moments_of[m.key] = m;
    std::vector<Eigen::Vector3d> by_class[kNumClasses];
    for (const Eigen::Vector3d& p : scan.source_in_body) {
      const registration::NdtCell* cells[7];
      const Eigen::Vector3d q = scan.T_world_body * p;
      if (target.neighbours(q, registration::NeighbourSearch::kDirect1, cells) == 0) continue;
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cells[0]->covariance);
      const double n_z = std::abs(solver.eigenvectors().col(0).z());
      by_class[n_z > 0.8 ? 0 : n_z < 0.3 ? 1 : 2].push_back(p);
      const double r = p.norm();
      by_class[r < 5 ? 3 : r < 10 ? 4 : r < 20 ? 5 : 6].push_back(p);
      if (cells[0]->stem) by_class[7].push_back(p);
      if (n_z < 0.3 && !cells[0]->stem) {
        const bool near_stem = distanceToStem(stems, q) < 0.1;
        by_class[near_stem ? 8 : 9].push_back(p);
        const auto found = moments_of.find(registration::voxelOf(q, 1.0 / o.resolution_m));
        if (near_stem && found != moments_of.end()) {
          const int gate =
              static_cast<int>(registration::stemGateOf(found->second, o.resolution_m));
          ++gate_counts[gate];
          by_class[10 + gate].push_back(p);
        }
      }
      ++num_points;
      if (n_z < 0.3) ++num_upright;
      if (cells[0]->stem) ++num_stem;
    }
    const auto all = registration::ndtDerivatives(scan.source_in_body, target, scan.T_world_body,
                                                  ndt, true, nullptr);
    const Eigen::FullPivLU<lie::Matrix6> lu(all.hessian);
    const Eigen::Matrix3d R = scan.T_world_body.rotation().matrix();
    const auto errorOf = [&](const lie::Vector6& g) {
      const lie::Vector6 delta = -lu.solve(g);
      return Eigen::Vector3d(R * delta.head<3>());
    };
    const Eigen::Vector3d total = errorOf(all.gradient);
    total_along_m.push_back(total.dot(forward));
    total_up_m.push_back(total.z());
    for (int c = 0; c < kNumClasses; ++c) {
      const auto part = registration::ndtDerivatives(by_class[c], target, scan.T_world_body, ndt,
                                                     false, nullptr);
      const Eigen::Vector3d e = errorOf(part.gradient);
      along_m[c].push_back(e.dot(forward));
      up_m[c].push_back(e.z());
    }
  }
  std::printf("%zu scans, %.2f m cells, one Newton step from the truth: along travel %+.3f mm, "
              "up %+.3f mm\n",
              total_along_m.size(), o.resolution_m, 1e3 * mean(total_along_m),
              1e3 * mean(total_up_m));
  for (int c = 0; c < kNumClasses; ++c)
    std::printf("  %-22s along %+.3f mm, up %+.3f mm\n", kClasses[c], 1e3 * mean(along_m[c]),
                1e3 * mean(up_m[c]));
  std::printf("  %zu source points in cells, %zu in upright ones, %zu in stem cells\n",
              num_points, num_upright, num_stem);
  const char* kGates[] = {"passes (a neighbour's cell)",
                          "few points",
                          "leaning or flat",
                          "no circle",
                          "radius",
                          "residual",
                          "short arc"};
  std::printf("  upright, other, stem: the gate their cell fails:");
  for (int g = 0; g < 7; ++g) std::printf(" %s %zu;", kGates[g], gate_counts[g]);
  std::printf("\n");
}

/// A lidar-only odometry with exact deskew: prediction from the true relative motion, a map of
/// the last num_keyframes keyframes at their estimated poses. Its Sim(3) scale against the truth.
void runOdometry(const Options& o, const std::vector<TrueScan>& scans) {
  std::vector<lie::SE3> T_world_body_estimate{scans[0].T_world_body};
  std::vector<std::size_t> keyframes{0};
  std::vector<Eigen::Vector3d> map_in_world, sensors;
  bool map_stale = true;
  for (std::size_t i = 1; i < scans.size(); ++i) {
    const lie::SE3 guess = T_world_body_estimate.back() *
                           (scans[i - 1].T_world_body.inverse() * scans[i].T_world_body);
    const bool view_per_scan = o.max_view_angle_deg < 180.0 && !o.view_from_keyframe;
    if (map_stale || view_per_scan) {
      const std::size_t first =
          keyframes.size() > static_cast<std::size_t>(o.num_keyframes)
              ? keyframes.size() - o.num_keyframes : 0;
      const std::vector<std::size_t> in_map(keyframes.begin() + first, keyframes.end());
      std::vector<lie::SE3> T_world_keyframe;
      for (std::size_t k : in_map) T_world_keyframe.push_back(T_world_body_estimate[k]);
      const Eigen::Vector3d viewpoint =
          (view_per_scan ? guess : T_world_body_estimate[keyframes.back()]).translation();
      sensors.clear();
      map_in_world =
          mapInWorld(scans, in_map, T_world_keyframe, viewpoint, o.max_view_angle_deg, &sensors);
      map_stale = false;
    }
    T_world_body_estimate.push_back(
        align(o, scans[i].source_in_body, map_in_world, guess, &sensors).T_target_source);
    const Eigen::Vector3d last_keyframe = T_world_body_estimate[keyframes.back()].translation();
    if ((T_world_body_estimate.back().translation() - last_keyframe).norm() >= 1.0) {
      keyframes.push_back(i);
      map_stale = true;
    }
  }
  Eigen::Matrix3Xd estimate(3, scans.size()), truth(3, scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) {
    estimate.col(i) = T_world_body_estimate[i].translation();
    truth.col(i) = scans[i].T_world_body.translation();
  }
  const Eigen::Matrix4d sim3 = Eigen::umeyama(estimate, truth, true);
  // The Sim(3) scale of an open trajectory also answers to its heading drift; the path length
  // ratio does not (eval/drift.hpp).
  std::vector<StampedPose> estimate_poses, true_poses;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    estimate_poses.push_back({0.1 * static_cast<double>(i), T_world_body_estimate[i]});
    true_poses.push_back({0.1 * static_cast<double>(i), scans[i].T_world_body});
  }
  std::printf(
      "%s odometry, %.2f m cells (coarse %.2f m), %d keyframes in the map: %zu scans, "
      "%zu keyframes, Sim(3) scale %.5f, path length ratio %.5f\n",
      o.method.c_str(), o.resolution_m, o.coarse_resolution_m, o.num_keyframes, scans.size(),
      keyframes.size(), std::cbrt(sim3.topLeftCorner<3, 3>().determinant()),
      eval::computeDrift(estimate_poses, true_poses).path_length_ratio);
}

/// groundtruth.tum against the regenerated motion, and the deskewed points (true poses) against
/// the regenerated scene, scaled about the body origin: the data are exact when 1.000 fits best.
void checkAgainstScene(const Options& o, const std::vector<TrueScan>& scans,
                       const Trajectory& truth) {
  sim::Scenario scenario;
  sim::applyScenarioOverrides(o.sim_dir + "/scenario.yaml", scenario);
  std::ifstream scene_json(o.sim_dir + "/scene.json");
  const auto seed = nlohmann::json::parse(scene_json)["seed"].get<std::uint64_t>();
  const sim::Simulation simulation(scenario, scenario.duration_s, seed);
  double worst_m = 0.0;
  for (const StampedPose& pose : truth.poses()) {
    const lie::SE3 T = simulation.motion().at(pose.t_s - truth.startTime()).T_world_body;
    worst_m = std::max(worst_m, (T.translation() - pose.pose.translation()).norm());
  }
  std::printf("groundtruth.tum against the simulator's motion: worst %.3f mm\n", 1e3 * worst_m);
  for (double scale : {0.995, 0.997, 0.999, 1.0, 1.001, 1.003, 1.005}) {
    std::vector<double> distances_m;
    for (std::size_t i = 0; i < scans.size(); i += 20)
      for (const Eigen::Vector3d& p : scans[i].map_in_body)
        if (p.norm() > 2.0 && p.norm() < 15.0)
          distances_m.push_back(
              simulation.scene().distanceToSurface(scans[i].T_world_body * (scale * p), 0.3));
    std::printf("points 2-15 m away scaled by %.3f: mean distance to the scene %.3f mm (%zu)\n",
                scale, 1e3 * mean(distances_m), distances_m.size());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bias of scan-to-map registration on a simulated recording with exact deskew"};
  Options o;
  bool odometry = false, scene_check = false, forces = false;
  app.add_option("sim", o.sim_dir, "taiga simulate output directory")->required();
  app.add_flag("--odometry", odometry, "run a lidar-only odometry and report its scale");
  app.add_flag("--forces", forces, "split the bias by surface and range (NDT gradient)");
  app.add_flag("--scene-check", scene_check, "check the data against the regenerated scene");
  app.add_option("--method", o.method, "ndt | d2d | gicp");
  app.add_option("--resolution", o.resolution_m, "NDT cell edge, m");
  app.add_option("--coarse", o.coarse_resolution_m, "a first NDT pass with these cells, m");
  app.add_option("--keyframes", o.num_keyframes, "keyframes in the map");
  app.add_option("--skip", o.skip_keyframes, "leave out the keyframes nearest the scan");
  app.add_flag("--ahead", o.map_ahead, "map from the keyframes after the scan");
  app.add_option("--every", o.every, "register every k-th scan (bias)");
  app.add_option("--max-view-angle", o.max_view_angle_deg,
                 "map points seen from their keyframe within this angle of the scan's view, deg");
  app.add_flag("--view-from-keyframe", o.view_from_keyframe,
               "--odometry: that angle from the latest keyframe, one map per keyframe");
  app.add_option("--src-min-z", o.source_min_z_m, "source points from this height (body), m");
  app.add_option("--src-max-z", o.source_max_z_m, "source points up to this height, m");
  app.add_option("--src-min-range", o.source_min_range_m, "source points from this range, m");
  app.add_option("--src-max-range", o.source_max_range_m, "source points up to this range, m");
  app.add_option("--range-scale", o.range_scale, "multiply every range (diagnosis)");
  app.add_option("--range-offset", o.range_offset_m, "add to every range, m (diagnosis)");
  app.add_flag("--world-voxels", o.world_voxels, "voxel grids fixed in the world (diagnosis)");
  app.add_option("--source-sample", o.source_sample,
                 "centroid | measured | bearing | raw (0.4 m voxels)");
  app.add_option("--map-sample", o.map_sample,
                 "centroid | measured | bearing | raw (0.2 m voxels)");
  app.add_option("--beam-noise", o.beam_sigma_m,
                 "stem cells take out this range noise of the map points, 1-sigma m");
  app.add_option("--beam-noise-per-m", o.beam_sigma_per_m, "and this much more per metre");
  app.add_option("--map-from", o.map_from, "map points from this simulation (diagnosis)");
  app.add_option("--source-noise", o.source_noise_m, "add range noise to the source, 1-sigma m");
  app.add_option("--map-noise", o.map_noise_m, "add range noise to the map points, 1-sigma m");
  app.add_flag("--stem-cells", o.stem_cells, "NDT stem cells (ndt.hpp)");
  app.add_flag("--stem-cells-across-borders", o.stem_cells_across_borders,
               "stem cells also from 2 x 2 blocks of cells (a stem cut by cell borders)");
  app.add_flag("--reverse", o.reverse, "also register the map to the scan (bias)");
  CLI11_PARSE(app, argc, argv);
  if (o.every < 1 || o.num_keyframes < 1 || o.skip_keyframes < 0) {
    std::fprintf(stderr, "--every and --keyframes must be >= 1, --skip >= 0\n");
    return 2;
  }

  SystemConfig config;
  io::readConfigYaml(o.sim_dir + "/rig.yaml", config);
  const Trajectory truth = io::readTum(o.sim_dir + "/groundtruth.tum");
  std::vector<TrueScan> scans = readTrueScans(o, config, truth);
  if (!o.map_from.empty()) {
    Options other = o;
    other.sim_dir = o.map_from;
    const std::vector<TrueScan> map_scans = readTrueScans(other, config, truth);
    if (map_scans.size() != scans.size()) {
      std::fprintf(stderr, "%s: %zu scans against %zu\n", o.map_from.c_str(), map_scans.size(),
                   scans.size());
      return 1;
    }
    for (std::size_t i = 0; i < scans.size(); ++i) scans[i].map_in_body = map_scans[i].map_in_body;
  }
  if (scans.size() < 3) {
    std::fprintf(stderr, "%s: fewer than 3 scans within the ground truth\n", o.sim_dir.c_str());
    return 1;
  }
  if (scene_check) checkAgainstScene(o, scans, truth);
  if (odometry) runOdometry(o, scans);
  else if (forces) measureForces(o, scans);
  else measureBias(o, scans);
  return 0;
}
