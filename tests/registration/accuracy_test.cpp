// Registration of the real scan pair from random initial errors up to 1 m and 10 degrees: every
// method must reach 5 cm and 0.5 degrees of the reference transform in at least 95 % of trials.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "registration_data.hpp"
#include "taiga/registration/registration.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

using test::kRegistrationData;

struct Pair {
  std::vector<Eigen::Vector3d> source, target;
  lie::SE3 T_target_source;
};

const Pair& pair() {
  static const Pair p = [] {
    Pair out;
    out.source = test::loadPositions(kRegistrationData / "source.ply");
    out.target = test::loadPositions(kRegistrationData / "target.ply");
    out.T_target_source = test::loadTransform(kRegistrationData / "T_target_source.txt");
    return out;
  }();
  return p;
}

struct Trials {
  int successes = 0;
  int trials = 0;
  double worst_success_m = 0.0;
  double worst_success_deg = 0.0;
};

Trials runTrials(const std::vector<Eigen::Vector3d>& source,
                 const std::vector<Eigen::Vector3d>& target, const lie::SE3& reference,
                 const RegistrationConfig& config, int num_trials, unsigned seed) {
  std::mt19937 rng(seed);
  Trials out;
  for (int i = 0; i < num_trials; ++i) {
    const lie::SE3 guess = reference * test::randomPerturbation(rng, 1.0, 10.0);
    const auto start = std::chrono::steady_clock::now();
    const RegistrationResult r = registerClouds(source, target, guess, config);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const test::PoseError e = test::poseError(r.T_target_source, reference);
    const test::PoseError e0 = test::poseError(guess, reference);
    const bool ok = e.translation_m < 0.05 && e.rotation_deg < 0.5;
    if (std::getenv("TAIGA_VERBOSE") != nullptr) {
      std::printf(
          "  %s trial %2d: start %.2f m %.1f deg -> %.4f m %.3f deg, %d it, %s%s, %.0f ms\n",
          methodName(config.method).c_str(), i, e0.translation_m, e0.rotation_deg, e.translation_m,
          e.rotation_deg, r.iterations,
          r.converged ? "converged" : "not converged: ", r.reason.c_str(), ms);
    }
    ++out.trials;
    if (ok) {
      ++out.successes;
      out.worst_success_m = std::max(out.worst_success_m, e.translation_m);
      out.worst_success_deg = std::max(out.worst_success_deg, e.rotation_deg);
    }
  }
  std::printf("%s: %d / %d within 5 cm and 0.5 deg (worst success %.4f m, %.3f deg)\n",
              methodName(config.method).c_str(), out.successes, out.trials, out.worst_success_m,
              out.worst_success_deg);
  return out;
}

constexpr int kTrials = 40;

TEST(Accuracy, NdtFromRandomInitialErrors) {
  RegistrationConfig config;
  config.method = Method::kNdt;
  config.ndt.resolution_m = 1.0;
  config.ndt.coarse_resolutions_m = {4.0, 2.0};
  const auto source = voxelDownsample(pair().source, 0.4);
  const Trials t = runTrials(source, pair().target, pair().T_target_source, config, kTrials, 1);
  EXPECT_GE(t.successes, 0.95 * t.trials);
}

TEST(Accuracy, D2dNdtFromRandomInitialErrors) {
  RegistrationConfig config;
  config.method = Method::kD2dNdt;
  config.ndt.resolution_m = 1.0;
  config.ndt.coarse_resolutions_m = {4.0, 2.0};
  const Trials t =
      runTrials(pair().source, pair().target, pair().T_target_source, config, kTrials, 2);
  EXPECT_GE(t.successes, 0.95 * t.trials);
}

TEST(Accuracy, GicpFromRandomInitialErrors) {
  RegistrationConfig config;
  config.method = Method::kGicp;
  const auto source = voxelDownsample(pair().source, 0.2);
  const auto target = voxelDownsample(pair().target, 0.2);
  const Trials t = runTrials(source, target, pair().T_target_source, config, kTrials, 3);
  EXPECT_GE(t.successes, 0.95 * t.trials);
}

}  // namespace
}  // namespace taiga::registration
