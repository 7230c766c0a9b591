// taiga register: align two point clouds.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>

#include "command.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"
#include "taiga/registration/registration.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/yaw_search.hpp"

namespace taiga::app {
namespace {
struct RegisterOptions {
  std::string source, target, guess;
  std::string method = "ndt";
  double resolution_m = 1.0;
  double voxel_m = 0.25;
  int yaw_hypotheses = 0;  ///< 0: 12 without --guess, 1 with
  bool json = false;
};

// A 4x4 homogeneous matrix, row by row, whitespace separated (as T_target_source.txt of the test
// data); the last row must be 0 0 0 1.
lie::SE3 readGuess(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the --guess file", path));
  Eigen::Matrix4d T;
  for (int i = 0; i < 16; ++i) {
    if (!(in >> T(i / 4, i % 4)) || !std::isfinite(T(i / 4, i % 4))) {
      throw InputError(fmt::format(
          "{}: expected 16 numbers (a 4x4 matrix T_target_source, row by row), value {} is "
          "missing or not a number",
          path, i + 1));
    }
  }
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw InputError(fmt::format("{}: the last row of the 4x4 matrix must be 0 0 0 1", path));
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3) {
    throw InputError(fmt::format("{}: the upper-left 3x3 block is not a rotation matrix", path));
  }
  return lie::SE3::fromMatrix(T);
}

std::vector<Eigen::Vector3d> readPositions(const std::string& path, const std::string& what) {
  std::vector<Eigen::Vector3d> points = io::readPointCloudFile(path, 0.0).cloud.positions;
  if (points.empty())
    throw InputError(fmt::format("{}: the {} cloud has no valid point", path, what));
  return points;
}

std::string finiteOrNull(double value) {
  return std::isfinite(value) ? fmt::format("{:.6g}", value) : "null";
}

std::string formatResult(const RegisterOptions& o, const registration::YawSearchResult& search,
                         double time_ms, std::size_t n_source, std::size_t n_target) {
  const registration::RegistrationResult& r = search.best;
  const Eigen::Matrix4d T = r.T_target_source.matrix();
  // R = Rz(yaw) Ry(pitch) Rx(roll), as lie::SO3::fromRollPitchYaw.
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d rpy_deg =
      Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
                      r.T_target_source.rotation().yaw()) *
      kDegPerRad;
  std::string out;
  if (o.json) {
    std::string rows;
    for (int i = 0; i < 4; ++i) {
      rows += fmt::format("{}[{:.12g}, {:.12g}, {:.12g}, {:.12g}]", i ? ", " : "", T(i, 0), T(i, 1),
                          T(i, 2), T(i, 3));
    }
    const std::string fitness =
        std::isfinite(r.fitness_m2) ? fmt::format("{:.9g}", r.fitness_m2) : "null";
    const std::string condition =
        std::isfinite(r.hessian_condition) ? fmt::format("{:.6g}", r.hessian_condition) : "null";
    std::string reason;
    for (char c : r.reason) {
      if (c == '"' || c == '\\') reason += '\\';
      reason += c;
    }
    out = fmt::format(
        "{{\"method\": \"{}\", \"T_target_source\": [{}], \"converged\": {}, \"reason\": \"{}\", "
        "\"iterations\": {}, \"num_inliers\": {}, \"fitness_m2\": {}, \"hessian_condition\": {}, "
        "\"translation_condition\": {}, \"overlap\": {:.4f}, \"ambiguous\": {}, "
        "\"yaw_hypotheses\": {}, \"time_ms\": {:.3f}, \"source_points\": {}, "
        "\"target_points\": {}}}\n",
        o.method, rows, r.converged, reason, r.iterations, r.num_inliers, fitness, condition,
        finiteOrNull(r.translation_condition), search.overlap, search.ambiguous, search.hypotheses,
        time_ms, n_source, n_target);
  } else {
    out += fmt::format("method: {}\nT_target_source:\n", o.method);
    for (int i = 0; i < 4; ++i) {
      out += fmt::format("  {:14.9f} {:14.9f} {:14.9f} {:14.6f}\n", T(i, 0), T(i, 1), T(i, 2),
                         T(i, 3));
    }
    out += fmt::format("translation_m: {:.6f} {:.6f} {:.6f}\n", T(0, 3), T(1, 3), T(2, 3));
    out += fmt::format("roll_pitch_yaw_deg: {:.4f} {:.4f} {:.4f}\n", rpy_deg.x(), rpy_deg.y(),
                       rpy_deg.z());
    out += fmt::format("converged: {}{}\n", r.converged ? "yes" : "no",
                       r.reason.empty() ? "" : " (" + r.reason + ")");
    out += fmt::format("iterations: {}\ninliers: {}\nfitness_m2: {:.6f}\n", r.iterations,
                       r.num_inliers, r.fitness_m2);
    out += fmt::format("overlap: {:.1f} % of the source within {} m of the target\n",
                       100.0 * search.overlap, registration::YawSearchOptions{}.inlier_distance_m);
    out += fmt::format(
        "yaw_hypotheses: {}{}\n", search.hypotheses,
        search.rival_overlap > 0.0
            ? fmt::format(" (best distinct rival: {:.1f} % overlap, {:.2f} m / "
                          "{:.1f} deg away)",
                          100.0 * search.rival_overlap, search.rival_m, search.rival_deg)
            : std::string());
    out +=
        fmt::format("hessian_condition: {:.4g}\ntime_ms: {:.1f}\n", r.hessian_condition, time_ms);
  }
  return out;
}

int runRegister(const RegisterOptions& o) {
  registration::RegistrationConfig config;
  config.method = *registration::methodFromName(o.method);
  config.ndt.resolution_m = o.resolution_m;
  config.ndt.coarse_resolutions_m = {4.0 * o.resolution_m, 2.0 * o.resolution_m};
  const lie::SE3 guess = o.guess.empty() ? lie::SE3() : readGuess(o.guess);
  std::vector<Eigen::Vector3d> source = readPositions(o.source, "source");
  std::vector<Eigen::Vector3d> target = readPositions(o.target, "target");
  const auto start = std::chrono::steady_clock::now();
  if (o.voxel_m > 0.0) {
    source = registration::voxelDownsample(source, o.voxel_m);
    // NDT cells need several target points each, so only GICP thins the target.
    if (config.method == registration::Method::kGicp) {
      target = registration::voxelDownsample(target, o.voxel_m);
    }
  }
  // Without a guess the identity may be far off: several headings, and ambiguity reported.
  const int hypotheses = o.yaw_hypotheses > 0 ? o.yaw_hypotheses : (o.guess.empty() ? 12 : 1);
  const registration::YawSearchResult search = registration::registerWithYawSearch(
      source, target, guess, config, {.hypotheses = hypotheses});
  const double time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  fmt::print("{}", formatResult(o, search, time_ms, source.size(), target.size()));
  return search.best.converged ? kExitOk : kExitFailure;
}
}  // namespace

Command addRegisterCommand(CLI::App& tool) {
  auto options = std::make_shared<RegisterOptions>();
  CLI::App* parser = tool.add_subcommand(
      "register", "Align SOURCE to TARGET and print T_target_source, fitness, iterations and time");
  parser->add_option("SOURCE", options->source, "Point cloud to move (PCD or PLY)")->required();
  parser->add_option("TARGET", options->target, "Point cloud to align to (PCD or PLY)")->required();
  parser->add_option("--method", options->method, "Registration method")
      ->check(CLI::IsMember({"ndt", "d2d", "gicp"}))
      ->capture_default_str();
  parser->add_option("--guess", options->guess, "Initial T_target_source (4x4 matrix text file)");
  parser
      ->add_option("--resolution", options->resolution_m,
                   "NDT cell size, m (coarse to fine from 4x and 2x this size)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  parser
      ->add_option(
          "--voxel", options->voxel_m,
          "Voxel-grid leaf for the source (and for GICP the target), m; 0 keeps all points")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  parser
      ->add_option("--yaw-hypotheses", options->yaw_hypotheses,
                   "Start from this many headings about the guess (360/N deg apart) and keep the "
                   "best overlap; a distinct solution nearly as good is reported as ambiguous "
                   "(not converged). Default: 12 without --guess, 1 with")
      ->check(CLI::Range(1, 360));
  parser->add_flag("--json", options->json, "Print JSON instead of text");
  return {parser, [options] { return runRegister(*options); }, options};
}

}  // namespace taiga::app
