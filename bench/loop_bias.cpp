// Is a loop closure's relative pose biased, and by what? The loop-closed trajectory of a
// handheld-loop comes out shorter than its own odometry (docs/registration.md, "Bias"). This
// program registers keyframes of a finished run to submaps built at their *true* poses, as the
// loop closure does (loopRegistrationConfig, the keyframe store's registration copies), from the
// true relative pose, so that any error left is the registration's.
//
//   loop_bias SIM RUN                 every --every-th keyframe k against submaps of the keyframes
//                                     ahead of it [k+gap, k+gap+width), behind it, and on both
//                                     sides (half the width each)
//   loop_bias SIM RUN --loops         the run's accepted loops (RUN/loops.csv), each against its
//                                     candidate's submap as the run built it
//     [--poses RUN/trajectory_odometry.tum]   the submaps and guesses at these poses instead
//     [--graph PREFIX]                        and the mapping graph solved with the loops as
//                                             measured and as true (PREFIX_*.tum for taiga eval)
//   loop_bias SIM RUN --poses F --relative K  F's relative poses to keyframe K against the truth
//
// (bench/BENCHMARK.md, "Session 66": the loop closure does not add to the shrink.)
// Reported per arrangement: the mean and spread of the translation error, in the keyframe's body
// frame and along the unit vector from the keyframe to the mean of the submap's keyframe
// positions ("toward the viewpoints": positive when the keyframe is placed toward them).
// SIM: a `taiga simulate` output with `ideal` realism (keyframe times on the truth's clock).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "taiga/core/system_config.hpp"
#include "taiga/core/trajectory.hpp"
#include "taiga/io/config_yaml.hpp"
#include "taiga/io/trajectory_io.hpp"
#include "taiga/mapping/keyframe_store.hpp"
#include "taiga/mapping/loop_closure.hpp"
#include "taiga/mapping/pose_graph.hpp"
#include "taiga/preprocess/voxel_filter.hpp"
#include "taiga/registration/registration.hpp"

using namespace taiga;

namespace {

struct Options {
  std::string sim_dir, run_dir;
  bool loops = false;
  int every = 3, gap = 2, width = 10;
  /// The submap's points: the store's registration copies (0: as the run) or the keyframes'
  /// full scans voxel-filtered at this size with `submap_point`.
  double submap_voxel_m = 0.0;
  std::string submap_point = "centroid";
  /// The submap's keyframe poses and the guess from this TUM file (e.g. the run's
  /// trajectory_odometry.tum, as the graph held them before the first loop) instead of the truth.
  std::string poses_file;
  int true_first = 0;  ///< keyframes before this one placed by the truth relative to it
};

struct Case {
  std::size_t current = 0;
  double fitness_m2 = 0.0;          ///< --loops: the run's
  std::vector<std::size_t> submap;  ///< keyframe ids; the first is the submap's frame
};

struct Error {
  lie::SE3 T_frame_current;  ///< the registration's, frame = the submap's first keyframe
  Eigen::Vector3d in_body = Eigen::Vector3d::Zero();  ///< m, current keyframe's body frame
  double toward_viewpoints_m = 0.0;
  bool converged = false;
};

class Bench {
 public:
  Bench(const Options& o, const SystemConfig& config)
      : o_(o),
        config_(config),
        store_(mapping::KeyframeStore::open(
            o.run_dir + "/keyframes", {.registration_voxel_m = config.odometry.voxel_size_m,
                                       .registration_voxel_point = preprocess::voxelRepresentative(
                                           config.odometry.voxel_point)})) {
    const Trajectory truth = io::readTum(o.sim_dir + "/groundtruth.tum");
    for (std::size_t k = 0; k < store_.size(); ++k)
      T_world_body_.push_back(truth.poseAt(store_.info(k).t_s));
    T_map_body_ = T_world_body_;
    if (!o.poses_file.empty()) {
      const Trajectory poses = io::readTum(o.poses_file);
      for (std::size_t k = 0; k < store_.size(); ++k)
        T_map_body_[k] = poses.poseAt(store_.info(k).t_s);
    }
    // Diagnosis: the first keyframes placed by the truth relative to keyframe `true_first`.
    for (std::size_t k = 0; k < static_cast<std::size_t>(o.true_first); ++k)
      T_map_body_[k] =
          T_map_body_[o.true_first] * T_world_body_[o.true_first].inverse() * T_world_body_[k];
  }
  std::size_t size() const { return store_.size(); }
  const lie::SE3& truePose(std::size_t k) const { return T_world_body_[k]; }
  const lie::SE3& pose(std::size_t k) const { return T_map_body_[k]; }
  double time(std::size_t k) const { return store_.info(k).t_s; }

  /// The --poses' relative pose of every keyframe to `base` against the truth's.
  void printRelativeErrors(std::size_t base) const {
    for (std::size_t k = 0; k < size(); ++k) {
      const lie::SE3 est = T_map_body_[base].inverse() * T_map_body_[k];
      const lie::SE3 tru = T_world_body_[base].inverse() * T_world_body_[k];
      const Eigen::Vector3d dt = est.translation() - tru.translation();
      const Eigen::Vector3d dr = (tru.rotation().inverse() * est.rotation()).Log();
      const Eigen::Vector3d z_est = T_map_body_[k].rotation() * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d z_tru = T_world_body_[k].rotation() * Eigen::Vector3d::UnitZ();
      std::printf(
          "%3zu  %6.2f m  t error (%+6.1f %+6.1f %+6.1f) mm  r error (%+6.1f %+6.1f %+6.1f) "
          "mdeg  tilt %5.1f mdeg\n",
          k, tru.translation().norm(), 1e3 * dt.x(), 1e3 * dt.y(), 1e3 * dt.z(),
          1e3 * dr.x() * 180 / M_PI, 1e3 * dr.y() * 180 / M_PI, 1e3 * dr.z() * 180 / M_PI,
          1e3 * std::acos(std::clamp(z_est.dot(z_tru), -1.0, 1.0)) * 180 / M_PI);
    }
  }

  Error measure(const Case& c) const {
    const lie::SE3 T_frame_map = T_map_body_[c.submap.front()].inverse();
    std::vector<Eigen::Vector3d> submap_in_frame;
    Eigen::Vector3d viewpoints_in_world = Eigen::Vector3d::Zero();
    for (std::size_t k : c.submap) {
      const lie::SE3 T_frame_k = T_frame_map * T_map_body_[k];
      for (const Eigen::Vector3d& p_k : submapPoints(k)) submap_in_frame.push_back(T_frame_k * p_k);
      viewpoints_in_world += T_world_body_[k].translation();
    }
    viewpoints_in_world /= static_cast<double>(c.submap.size());

    const lie::SE3 T_frame_current_true =
        T_world_body_[c.submap.front()].inverse() * T_world_body_[c.current];
    const registration::RegistrationResult r = registration::registerClouds(
        store_.registrationCloud(c.current)->positions, submap_in_frame,
        T_frame_map * T_map_body_[c.current], mapping::loopRegistrationConfig(config_.odometry));
    Error e;
    e.T_frame_current = r.T_target_source;
    e.converged = r.converged;
    // The estimated position of the current keyframe minus the true one, in the world frame.
    const Eigen::Vector3d error_in_world =
        T_world_body_[c.submap.front()].rotation() *
        (r.T_target_source.translation() - T_frame_current_true.translation());
    e.in_body = T_world_body_[c.current].rotation().inverse() * error_in_world;
    const Eigen::Vector3d toward = viewpoints_in_world - T_world_body_[c.current].translation();
    if (toward.norm() > 1e-6) e.toward_viewpoints_m = error_in_world.dot(toward.normalized());
    return e;
  }

 private:
  std::vector<Eigen::Vector3d> submapPoints(std::size_t k) const {
    if (o_.submap_voxel_m <= 0.0) return store_.registrationCloud(k)->positions;
    return preprocess::voxelFilter(store_.load(k), o_.submap_voxel_m,
                                   preprocess::voxelRepresentative(o_.submap_point))
        .positions;
  }

  const Options& o_;
  const SystemConfig& config_;
  mapping::KeyframeStore store_;
  std::vector<lie::SE3> T_world_body_;
  std::vector<lie::SE3> T_map_body_;  ///< the submap's poses: the truth or --poses
};

void report(const char* name, const std::vector<Error>& errors) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), mean_sq = Eigen::Vector3d::Zero();
  double toward = 0.0, toward_sq = 0.0;
  int n = 0, failed = 0;
  for (const Error& e : errors) {
    if (!e.converged) {
      ++failed;
      continue;
    }
    ++n;
    mean += e.in_body;
    mean_sq += e.in_body.cwiseProduct(e.in_body);
    toward += e.toward_viewpoints_m;
    toward_sq += e.toward_viewpoints_m * e.toward_viewpoints_m;
  }
  if (n == 0) {
    std::printf("%-8s no converged case (%d failed)\n", name, failed);
    return;
  }
  mean /= n;
  toward /= n;
  const Eigen::Vector3d sd = (mean_sq / n - mean.cwiseProduct(mean)).cwiseMax(0.0).cwiseSqrt();
  const double toward_sd = std::sqrt(std::max(0.0, toward_sq / n - toward * toward));
  std::printf(
      "%-8s n %3d (failed %d)  body x %+6.2f (sd %5.2f)  y %+6.2f (%5.2f)  z %+6.2f (%5.2f) mm"
      "  toward viewpoints %+6.2f (sd %5.2f, se %4.2f) mm\n",
      name, n, failed, 1e3 * mean.x(), 1e3 * sd.x(), 1e3 * mean.y(), 1e3 * sd.y(), 1e3 * mean.z(),
      1e3 * sd.z(), 1e3 * toward, 1e3 * toward_sd,
      1e3 * toward_sd / std::sqrt(static_cast<double>(n)));
}

std::vector<Case> runLoops(const Options& o, const SystemConfig& config, std::size_t size) {
  std::ifstream in(o.run_dir + "/loops.csv");
  if (!in) throw std::runtime_error(o.run_dir + "/loops.csv: cannot open");
  std::string line;
  std::getline(in, line);  // header
  std::vector<Case> cases;
  const auto half = static_cast<std::size_t>(config.mapping.loop_submap_keyframes);
  const auto excluded = static_cast<std::size_t>(config.mapping.loop_exclude_recent_keyframes);
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    if (fields.size() < 10 || fields[9] != "1") continue;
    Case c{.current = std::stoul(fields[1]), .fitness_m2 = std::stod(fields[5])};
    const std::size_t candidate = std::stoul(fields[2]);
    if (c.current >= size) continue;
    // As verifyLoop: the candidate's frame first, then its neighbours.
    c.submap.push_back(candidate);
    const std::size_t first = candidate >= half ? candidate - half : 0;
    const std::size_t last = std::min(candidate + half, c.current - excluded);
    for (std::size_t k = first; k <= last; ++k)
      if (k != candidate) c.submap.push_back(k);
    cases.push_back(c);
  }
  return cases;
}

/// The mapping graph of the --poses keyframes with the run's loops, loop i's relative pose
/// T_frame_current[i]; its keyframe poses written to `path` (TUM) for `taiga eval`.
void solveGraph(const Bench& bench, const SystemConfig& config, const std::vector<Case>& cases,
                const std::vector<lie::SE3>& T_frame_current, const std::string& path) {
  mapping::PoseGraph graph(config.mapping);
  for (std::size_t k = 0; k < bench.size(); ++k) graph.addKeyframe(bench.pose(k));
  for (std::size_t i = 0; i < cases.size(); ++i)
    graph.addLoop({cases[i].submap.front(), cases[i].current, T_frame_current[i],
                   mapping::loopCovariance(config.odometry, cases[i].fitness_m2)});
  graph.optimize();
  Trajectory keyframes;
  for (std::size_t k = 0; k < bench.size(); ++k) keyframes.append(bench.time(k), graph.pose(k));
  io::writeTum(path, keyframes);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bias of the loop closure's registration against the truth"};
  Options o;
  app.add_option("sim", o.sim_dir, "taiga simulate output")->required();
  app.add_option("run", o.run_dir, "taiga run output (keyframes/, loops.csv)")->required();
  app.add_flag("--loops", o.loops, "the run's accepted loops instead of the sweep");
  app.add_option("--every", o.every, "sweep: every k-th keyframe");
  app.add_option("--gap", o.gap, "sweep: keyframes left out next to k");
  app.add_option("--width", o.width, "sweep: keyframes in a submap");
  app.add_option("--submap-voxel", o.submap_voxel_m, "submap from full scans at this voxel, m");
  app.add_option("--submap-point", o.submap_point, "centroid | measured | bearing");
  app.add_option("--poses", o.poses_file, "submap poses and guess from this TUM file");
  int relative_base = -1;
  app.add_option("--true-first", o.true_first, "place keyframes before N by the truth");
  std::vector<std::string> overlays;
  app.add_option("--config", overlays, "YAML files read over SIM/rig.yaml, in order");
  std::string graph_prefix;
  app.add_option("--graph", graph_prefix,
                 "--loops: solve the graph of --poses with the loops measured and with the true "
                 "loops; keyframe poses to PREFIX_{measured,true,odometry}.tum");
  app.add_option("--relative", relative_base, "print --poses' relative poses to this keyframe");
  CLI11_PARSE(app, argc, argv);

  SystemConfig config;
  io::readConfigYaml(o.sim_dir + "/rig.yaml", config);
  for (const std::string& overlay : overlays) io::readConfigYaml(overlay, config);
  const Bench bench(o, config);
  const auto n = static_cast<int>(bench.size());
  if (relative_base >= 0) {
    bench.printRelativeErrors(static_cast<std::size_t>(relative_base));
    return 0;
  }

  if (o.loops) {
    const std::vector<Case> cases = runLoops(o, config, bench.size());
    std::vector<Error> errors;
    for (const Case& c : cases) {
      errors.push_back(bench.measure(c));
      const Error& e = errors.back();
      std::printf("loop %zu -> %zu: body (%+.2f, %+.2f, %+.2f) mm, toward %+.2f mm\n", c.current,
                  c.submap.front(), 1e3 * e.in_body.x(), 1e3 * e.in_body.y(), 1e3 * e.in_body.z(),
                  1e3 * e.toward_viewpoints_m);
    }
    report("loops", errors);
    if (!graph_prefix.empty()) {
      std::vector<lie::SE3> measured, truth;
      for (std::size_t i = 0; i < cases.size(); ++i) {
        measured.push_back(errors[i].T_frame_current);
        truth.push_back(bench.truePose(cases[i].submap.front()).inverse() *
                        bench.truePose(cases[i].current));
      }
      solveGraph(bench, config, cases, measured, graph_prefix + "_measured.tum");
      solveGraph(bench, config, cases, truth, graph_prefix + "_true.tum");
      Trajectory odometry;
      for (std::size_t k = 0; k < bench.size(); ++k) odometry.append(bench.time(k), bench.pose(k));
      io::writeTum(graph_prefix + "_odometry.tum", odometry);
    }
    return 0;
  }
  std::vector<Error> ahead, behind, both;
  for (int k = o.gap + o.width; k + o.gap + o.width < n; k += o.every) {
    Case a{.current = static_cast<std::size_t>(k)}, b = a, s = a;
    for (int j = 0; j < o.width; ++j) {
      a.submap.push_back(static_cast<std::size_t>(k + o.gap + j));
      b.submap.push_back(static_cast<std::size_t>(k - o.gap - j));
      if (j < o.width / 2) {
        s.submap.push_back(static_cast<std::size_t>(k + o.gap + j));
        s.submap.push_back(static_cast<std::size_t>(k - o.gap - j));
      }
    }
    ahead.push_back(bench.measure(a));
    behind.push_back(bench.measure(b));
    both.push_back(bench.measure(s));
  }
  report("ahead", ahead);
  report("behind", behind);
  report("both", both);
  return 0;
}
