// The mapping graph on a synthetic 160 m loop whose odometry drifts in heading: one loop factor
// must pull the end back onto the start and spread the correction along the loop, and a false
// loop must be refused by the consistency check without touching the poses.
#include "taiga/mapping/pose_graph.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "taiga/core/angles.hpp"

namespace taiga::mapping {
namespace {

// 160 keyframes 1 m apart around a 40 m x 40 m square, turning 90 deg at each corner.
std::vector<lie::SE3> trueSquareLoop() {
  std::vector<lie::SE3> poses;
  lie::SE3 T_world_body;
  for (int k = 0; k < 160; ++k) {
    poses.push_back(T_world_body);
    const double yaw_step = (k % 40 == 39) ? 90.0 * kRadPerDeg : 0.0;
    T_world_body =
        T_world_body * lie::SE3::Exp((lie::Vector6() << 1, 0, 0, 0, 0, yaw_step).finished());
  }
  return poses;
}

// The odometry: true steps with a heading drift of 0.02 deg per metre (3.2 deg over the loop)
// and 0.3 % scale error, as a scan-to-local-map odometry accumulates them.
std::vector<lie::SE3> driftingOdometry(const std::vector<lie::SE3>& truth) {
  std::vector<lie::SE3> odometry{truth.front()};
  for (std::size_t k = 1; k < truth.size(); ++k) {
    lie::SE3 step = truth[k - 1].inverse() * truth[k];
    step = lie::SE3(step.rotation() * lie::SO3::Exp(Eigen::Vector3d(0, 0, 0.02 * kRadPerDeg)),
                    step.translation() * 1.003);
    odometry.push_back(odometry.back() * step);
  }
  return odometry;
}

double worstPositionError(const std::vector<lie::SE3>& estimate,
                          const std::vector<lie::SE3>& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k)
    worst = std::max(worst, (estimate[k].translation() - truth[k].translation()).norm());
  return worst;
}

RelativePose loopFromTruth(const std::vector<lie::SE3>& truth, std::size_t from, std::size_t to) {
  lie::Vector6 variances;
  variances << 1e-4, 1e-4, 1e-4, 1e-5, 1e-5, 1e-5;  // 1 cm, 0.18 deg
  return {from, to, truth[from].inverse() * truth[to], variances.asDiagonal().toDenseMatrix()};
}

PoseGraph graphOf(const std::vector<lie::SE3>& odometry) {
  PoseGraph graph{MappingConfig{}};
  for (const lie::SE3& pose : odometry) graph.addKeyframe(pose);
  return graph;
}

TEST(PoseGraph, ChainsTheOdometryUntilALoopArrives) {
  const std::vector<lie::SE3> truth = trueSquareLoop();
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  const PoseGraph graph = graphOf(odometry);
  ASSERT_EQ(graph.size(), truth.size());
  EXPECT_LT((graph.pose(159).translation() - odometry[159].translation()).norm(), 1e-9);
  double true_path_m = 0.0;
  for (std::size_t k = 1; k < truth.size(); ++k)
    true_path_m += (truth[k].translation() - truth[k - 1].translation()).norm();
  EXPECT_NEAR(graph.pathLength(159), true_path_m * 1.003, 1e-6);
  EXPECT_GT(worstPositionError(graph.poses(), truth), 1.0);  // the drift the loop must remove
}

TEST(PoseGraph, OneLoopClosureRemovesTheHeadingDrift) {
  const std::vector<lie::SE3> truth = trueSquareLoop();
  PoseGraph graph = graphOf(driftingOdometry(truth));
  const double drifted_m = worstPositionError(graph.poses(), truth);

  const double chi2 = graph.addLoopIfConsistent(loopFromTruth(truth, 0, 159), 50.0);
  EXPECT_LE(chi2, 50.0);
  ASSERT_EQ(graph.loops().size(), 1u);
  EXPECT_LT((graph.pose(159).translation() - truth[159].translation()).norm(), 0.05);
  // The correction is spread along the loop, not dumped on its last keyframe.
  EXPECT_LT(worstPositionError(graph.poses(), truth), 0.25 * drifted_m);
  EXPECT_EQ(graph.pose(0).translation(), truth[0].translation());  // the gauge stays put
}

TEST(PoseGraph, RefusesAFalseLoopAndKeepsItsPoses) {
  const std::vector<lie::SE3> truth = trueSquareLoop();
  PoseGraph graph = graphOf(driftingOdometry(truth));
  ASSERT_LE(graph.addLoopIfConsistent(loopFromTruth(truth, 0, 159), 50.0), 50.0);
  const std::vector<lie::SE3> before = graph.poses();

  // A place that looks alike 4 m and 20 deg away: to satisfy it the graph has to bend.
  RelativePose false_loop = loopFromTruth(truth, 20, 150);
  false_loop.T_from_to =
      false_loop.T_from_to *
      lie::SE3::Exp((lie::Vector6() << 4.0, 0.0, 0.0, 0.0, 0.0, 20 * kRadPerDeg).finished());
  EXPECT_GT(graph.addLoopIfConsistent(false_loop, 50.0), 50.0);
  EXPECT_EQ(graph.loops().size(), 1u);
  for (std::size_t k = 0; k < before.size(); ++k)
    EXPECT_EQ(graph.pose(k).translation(), before[k].translation()) << k;
}

TEST(PoseGraph, PositionFactorsPlaceTheGraph) {
  const std::vector<lie::SE3> truth = trueSquareLoop();
  PoseGraph graph = graphOf(truth);
  const Eigen::Vector3d shift(10.0, -5.0, 1.0);
  for (std::size_t k = 0; k < truth.size(); k += 10)
    graph.addPosition(k, truth[k].translation() + shift, Eigen::Matrix3d::Identity() * 0.25, 3.0);
  graph.optimize();
  for (std::size_t k = 0; k < truth.size(); ++k)
    EXPECT_LT((graph.pose(k).translation() - truth[k].translation() - shift).norm(), 0.01) << k;
}

// Two loops agree with each other over the short odometry between their ends however far the
// odometry drifted around the loop; one half a metre off does not; odometry across map segments
// says nothing.
TEST(PoseGraph, TwoLoopsAgreeOverTheShortOdometryBetweenTheirEnds) {
  const std::vector<lie::SE3> truth = trueSquareLoop();
  const PoseGraph graph = graphOf(driftingOdometry(truth));
  const RelativePose first = loopFromTruth(truth, 0, 150), second = loopFromTruth(truth, 3, 153);
  EXPECT_LT(graph.loopPairChi2(first, second), 3.0);
  RelativePose off = second;
  off.T_from_to = off.T_from_to * lie::SE3::Exp((lie::Vector6() << 0, 0.5, 0, 0, 0, 0).finished());
  EXPECT_GT(graph.loopPairChi2(first, off), 100.0);

  PoseGraph segmented{MappingConfig{}};
  const std::vector<lie::SE3> odometry = driftingOdometry(truth);
  for (std::size_t k = 0; k < odometry.size(); ++k) segmented.addKeyframe(odometry[k], k < 152);
  EXPECT_TRUE(std::isinf(segmented.loopPairChi2(first, second)));
}

TEST(PoseGraph, RotatingTheMapTurnsEveryPoseAndKeepsTheFactorsSatisfied) {
  // The odometry's frame 1.5 deg off level: the graph is levelled at the end by turning the
  // whole map (the odometry's final tilt estimate), which changes no relative factor.
  const std::vector<lie::SE3> truth = trueSquareLoop();
  PoseGraph graph = graphOf(driftingOdometry(truth));
  graph.addLoop(loopFromTruth(truth, 0, 159));
  const double cost = graph.optimize();
  const std::vector<lie::SE3> before = graph.poses();
  const lie::SO3 R_level = lie::SO3::Exp(Eigen::Vector3d(0.02, -0.015, 0.0));
  graph.setEnuMap(lie::SE3(lie::SO3::Exp(Eigen::Vector3d(0, 0, 0.5)), Eigen::Vector3d(3, 4, 5)));
  graph.rotateMap(R_level);
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_LT((graph.pose(k).translation() - R_level * before[k].translation()).norm(), 1e-9);
    EXPECT_LT((graph.pose(k).rotation().inverse() * R_level * before[k].rotation()).angle(), 1e-9);
  }
  // Relative factors only: the optimum is where it was (the cost of the turned poses).
  EXPECT_NEAR(graph.optimize(), cost, 1e-9 * std::max(1.0, cost));
  // T_enu_map keeps its yaw and translation, with the map's new tilt dropped.
  ASSERT_TRUE(graph.enuMap());
  EXPECT_LT(std::abs(graph.enuMap()->rotation().matrix()(2, 2) - 1.0), 1e-12);
}

}  // namespace
}  // namespace taiga::mapping
