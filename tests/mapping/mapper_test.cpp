// The mapping back end's loop handling on synthetic keyframes: Mapper with a stand-in verifier
// (loops consistent with the odometry are kept and pull the graph, false ones are refused by the
// chi^2 test, attempts are paced by keyframe time, none with loop closure off), and MappingThread
// against an inline Mapper on a small synthetic forest with the real verifier (the same map,
// the same snapshots).
#include "taiga/mapping/mapper.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "synthetic_forest.hpp"
#include "taiga/core/angles.hpp"

namespace taiga::mapping {
namespace {

using ::testing::StartsWith;

// ---------------------------------------------------------------------------------------------
// Mapper with a stand-in verifier

// `keyframes` keyframes 1 m apart around a 40 m x 40 m square (turning 90 deg left at each
// corner), on into a second lap past 160.
std::vector<lie::SE3> trueSquareWalk(int keyframes) {
  std::vector<lie::SE3> T_world_body;
  lie::SE3 pose;
  for (int k = 0; k < keyframes; ++k) {
    T_world_body.push_back(pose);
    const double yaw_step_rad = (k % 40 == 39) ? 90.0 * kRadPerDeg : 0.0;
    pose = pose * lie::SE3::Exp((lie::Vector6() << 1, 0, 0, 0, 0, yaw_step_rad).finished());
  }
  return T_world_body;
}

// The odometry of it: 0.015 deg/m heading drift (or `deg_per_m`) and 0.3 % long steps.
std::vector<lie::SE3> driftingOdometry(const std::vector<lie::SE3>& T_world_body_true,
                                       double deg_per_m = 0.015) {
  std::vector<lie::SE3> T_odom_body{T_world_body_true.front()};
  for (std::size_t k = 1; k < T_world_body_true.size(); ++k) {
    const lie::SE3 step = T_world_body_true[k - 1].inverse() * T_world_body_true[k];
    T_odom_body.push_back(
        T_odom_body.back() *
        lie::SE3(step.rotation() * lie::SO3::Exp(Eigen::Vector3d(0, 0, deg_per_m * kRadPerDeg)),
                 step.translation() * 1.003));
  }
  return T_odom_body;
}

// A verifier that does not register anything: it reports the true relative pose from the
// candidate to the current keyframe, times `error` (in the current keyframe's frame), as a
// verified loop with the sigmas of a good registration (1 cm, 0.003 rad), or rejects every
// candidate when `accept` is false. It records the keyframes it was asked about in `asked`.
LoopVerifier reportTrueLoop(const std::vector<lie::SE3>& T_world_body_true, const lie::SE3& error,
                            std::vector<std::size_t>* asked, bool accept = true) {
  return [=](const PoseGraph&, const KeyframeStore&, std::size_t current,
             const LoopCandidate& candidate, const MappingConfig&, const OdometryConfig&) {
    asked->push_back(current);
    lie::Vector6 variances;
    variances << 1e-4, 1e-4, 1e-4, 9e-6, 9e-6, 9e-6;
    const lie::SE3 T_candidate_current =
        T_world_body_true[candidate.keyframe].inverse() * T_world_body_true[current] * error;
    LoopAttempt attempt{.current = current, .candidate = candidate, .accepted = accept};
    if (!accept) attempt.note = "stand-in: rejected";
    attempt.loop = RelativePose{candidate.keyframe, current, T_candidate_current,
                                variances.asDiagonal().toDenseMatrix()};
    return attempt;
  };
}

// Keyframe k at t = k s (1 m/s).
double secondsOf(std::size_t k) { return static_cast<double>(k); }

// Feeds keyframes until the mapper has made its first loop attempt; returns that keyframe.
std::optional<std::size_t> feedUntilFirstAttempt(Mapper& mapper,
                                                 const std::vector<lie::SE3>& T_odom_body) {
  for (std::size_t k = 0; k < T_odom_body.size(); ++k) {
    mapper.addKeyframe(k, secondsOf(k), T_odom_body[k]);
    if (!mapper.loopAttempts().empty()) return k;
  }
  return std::nullopt;
}

double distanceM(const lie::SE3& a, const lie::SE3& b) {
  return (a.translation() - b.translation()).norm();
}

class MapperWithAStandInVerifier : public ::testing::Test {
 protected:
  const std::vector<lie::SE3> T_world_body_true_ = trueSquareWalk(160);
  const std::vector<lie::SE3> T_odom_body_ = driftingOdometry(T_world_body_true_);
  const MappingConfig config_;  // the defaults: 40 excluded, 5 m + 0.02 m/m, chi^2 <= 50
  const taiga::test::TempDir dir_;
  const KeyframeStore store_ = KeyframeStore::create(dir_.path());  // the stand-in reads nothing
  std::vector<std::size_t> asked_;
};

TEST_F(MapperWithAStandInVerifier, KeepsALoopConsistentWithTheOdometryAndMovesTheKeyframeOntoIt) {
  Mapper mapper(config_, OdometryConfig{}, store_,
                reportTrueLoop(T_world_body_true_, lie::SE3(), &asked_));
  const std::optional<std::size_t> current = feedUntilFirstAttempt(mapper, T_odom_body_);
  ASSERT_TRUE(current.has_value());
  ASSERT_EQ(asked_, std::vector<std::size_t>{*current});
  const double drift_m = distanceM(T_odom_body_[*current], T_world_body_true_[*current]);
  ASSERT_GT(drift_m, 0.5);  // what the loop has to remove

  const LoopRecord& record = mapper.loopAttempts().front();
  EXPECT_TRUE(record.attempt.accepted);
  EXPECT_EQ(record.attempt.note, "");
  EXPECT_EQ(record.t_s, secondsOf(*current));
  EXPECT_GT(record.chi2, 0.0);
  EXPECT_LE(record.chi2, config_.loop_max_chi2);
  ASSERT_EQ(mapper.loopClosures(), 1u);
  const RelativePose& loop = mapper.graph().loops().front();
  EXPECT_EQ(loop.to, *current);
  EXPECT_EQ(loop.from, record.attempt.candidate.keyframe);

  // The current keyframe now sits where the loop puts it, on the truth, not on the odometry.
  const lie::SE3 T_world_current_by_loop = mapper.graph().pose(loop.from) * loop.T_from_to;
  EXPECT_LT(distanceM(mapper.graph().pose(*current), T_world_current_by_loop), 0.05);
  EXPECT_LT(distanceM(mapper.graph().pose(*current), T_world_body_true_[*current]), 0.1 * drift_m);
  EXPECT_EQ(mapper.graph().pose(0).translation(), T_odom_body_[0].translation());  // gauge
}

TEST_F(MapperWithAStandInVerifier, RefusesALoopFiveMetresOffAsInconsistentWithTheGraph) {
  const lie::SE3 five_m_off =
      lie::SE3::Exp((lie::Vector6() << 5.0, 0.0, 0.0, 0.0, 0.0, 0.0).finished());
  Mapper mapper(config_, OdometryConfig{}, store_,
                reportTrueLoop(T_world_body_true_, five_m_off, &asked_));
  const std::optional<std::size_t> current = feedUntilFirstAttempt(mapper, T_odom_body_);
  ASSERT_TRUE(current.has_value());

  const LoopRecord& record = mapper.loopAttempts().front();
  EXPECT_FALSE(record.attempt.accepted);  // verified, then refused by the graph
  EXPECT_GT(record.chi2, config_.loop_max_chi2);
  EXPECT_THAT(record.attempt.note, StartsWith("inconsistent with the graph: chi2 "));
  EXPECT_EQ(mapper.loopClosures(), 0u);
  // The graph still follows the odometry.
  for (std::size_t k = 0; k <= *current; ++k)
    EXPECT_LT(distanceM(mapper.graph().pose(k), T_odom_body_[k]), 1e-9) << k;
}

TEST_F(MapperWithAStandInVerifier, SpacesItsAttemptsByTheMinimumIntervalOfKeyframeTime) {
  // Past the start into a second lap, so that every keyframe from the first with a candidate on
  // has one. Keyframes 0.5 s apart up to keyframe 180, then 2 s apart.
  const std::vector<lie::SE3> T_world_body_true = trueSquareWalk(200);
  const std::vector<lie::SE3> T_odom_body = driftingOdometry(T_world_body_true);
  const auto time_s = [](std::size_t k) {
    return k <= 180 ? 0.5 * static_cast<double>(k) : 90.0 + 2.0 * static_cast<double>(k - 180);
  };
  Mapper mapper(config_, OdometryConfig{}, store_,
                reportTrueLoop(T_world_body_true, lie::SE3(), &asked_, /*accept=*/false));
  PoseGraph odometry_only(config_);  // where the candidates are: no loop is ever kept
  std::optional<std::size_t> first_with_candidate;
  for (std::size_t k = 0; k < T_odom_body.size(); ++k) {
    mapper.addKeyframe(k, time_s(k), T_odom_body[k]);
    odometry_only.addKeyframe(T_odom_body[k]);
    const bool has_candidate = findLoopCandidate(odometry_only, k, config_).has_value();
    if (has_candidate && !first_with_candidate) first_with_candidate = k;
    if (first_with_candidate) {
      ASSERT_TRUE(has_candidate) << k;
    }
  }
  ASSERT_TRUE(first_with_candidate.has_value());
  ASSERT_LT(*first_with_candidate, 170u);

  // The first keyframe with a candidate is tried at once, then every keyframe at least
  // loop_min_interval_s (1.5 s) after the last attempt: every third at 0.5 s, every one at 2 s.
  std::vector<std::size_t> expected{*first_with_candidate};
  for (std::size_t k = *first_with_candidate + 1; k < T_odom_body.size(); ++k)
    if (time_s(k) - time_s(expected.back()) >= config_.loop_min_interval_s) expected.push_back(k);
  EXPECT_EQ(asked_, expected);
  EXPECT_EQ(expected[1] - expected[0], 3u);
  EXPECT_EQ(expected.back() - expected[expected.size() - 2], 1u);
  ASSERT_EQ(mapper.loopAttempts().size(), asked_.size());
  for (std::size_t i = 0; i < asked_.size(); ++i) {
    EXPECT_EQ(mapper.loopAttempts()[i].t_s, time_s(asked_[i]));
    EXPECT_EQ(mapper.loopAttempts()[i].attempt.note, "stand-in: rejected");
  }
  EXPECT_EQ(mapper.loopClosures(), 0u);
}

// A rig whose odometry drifts more than the graph's sigmas allow (0.03 deg/m): its true loops
// are disputed by the graph, but two that agree with each other are both kept.
TEST_F(MapperWithAStandInVerifier, KeepsTwoDisputedLoopsThatAgreeWithEachOther) {
  const std::vector<lie::SE3> T_odom_body = driftingOdometry(T_world_body_true_, 0.03);
  Mapper mapper(config_, OdometryConfig{}, store_,
                reportTrueLoop(T_world_body_true_, lie::SE3(), &asked_));
  for (std::size_t k = 0; k < T_odom_body.size(); ++k)
    mapper.addKeyframe(k, secondsOf(k), T_odom_body[k]);
  const std::vector<LoopRecord>& attempts = mapper.loopAttempts();
  ASSERT_GE(attempts.size(), 2u);
  // Each alone is beyond the limit; the second finds the first agreeing and both are kept.
  EXPECT_GT(attempts[0].chi2, config_.loop_max_chi2);
  EXPECT_GT(attempts[1].chi2, config_.loop_max_chi2);
  EXPECT_TRUE(attempts[0].attempt.accepted);
  EXPECT_TRUE(attempts[1].attempt.accepted);
  EXPECT_THAT(attempts[1].attempt.note,
              StartsWith("accepted with the loop at keyframe " + std::to_string(asked_[0])));
  ASSERT_GE(mapper.loopClosures(), 2u);
  const std::size_t second = asked_[1];
  const double drift_m = distanceM(T_odom_body[second], T_world_body_true_[second]);
  ASSERT_GT(drift_m, 2.0);
  EXPECT_LT(distanceM(mapper.graph().pose(second), T_world_body_true_[second]), 0.05 * drift_m);
}

// The same rig, with its first loop a registration's wrong minimum half a metre to the side: the
// next (true) loop does not agree with it, and the one after agrees with the next; the false
// loop is never kept.
TEST_F(MapperWithAStandInVerifier, NeverPairsADisputedLoopWithOneThatContradictsIt) {
  const std::vector<lie::SE3> T_odom_body = driftingOdometry(T_world_body_true_, 0.03);
  const LoopVerifier truth = reportTrueLoop(T_world_body_true_, lie::SE3(), &asked_);
  const LoopVerifier half_metre_off = reportTrueLoop(
      T_world_body_true_, lie::SE3::Exp((lie::Vector6() << 0, 0.5, 0, 0, 0, 0).finished()),
      &asked_);
  int calls = 0;
  Mapper mapper(config_, OdometryConfig{}, store_,
                [&](const PoseGraph& graph, const KeyframeStore& store, std::size_t current,
                    const LoopCandidate& candidate, const MappingConfig& config,
                    const OdometryConfig& odometry) {
                  return (calls++ == 0 ? half_metre_off : truth)(graph, store, current, candidate,
                                                                 config, odometry);
                });
  for (std::size_t k = 0; k < T_odom_body.size(); ++k)
    mapper.addKeyframe(k, secondsOf(k), T_odom_body[k]);
  const std::vector<LoopRecord>& attempts = mapper.loopAttempts();
  ASSERT_GE(attempts.size(), 3u);
  EXPECT_FALSE(attempts[0].attempt.accepted);
  EXPECT_THAT(attempts[0].attempt.note, StartsWith("inconsistent with the graph"));
  EXPECT_TRUE(attempts[2].attempt.accepted);
  EXPECT_THAT(attempts[2].attempt.note,
              StartsWith("accepted with the loop at keyframe " + std::to_string(asked_[1])));
  for (const RelativePose& loop : mapper.graph().loops()) EXPECT_NE(loop.to, asked_[0]);
}

TEST_F(MapperWithAStandInVerifier, MakesNoAttemptWithLoopClosureOff) {
  MappingConfig config = config_;
  config.loop_closure = false;
  Mapper mapper(config, OdometryConfig{}, store_,
                reportTrueLoop(T_world_body_true_, lie::SE3(), &asked_));
  for (std::size_t k = 0; k < T_odom_body_.size(); ++k)
    mapper.addKeyframe(k, secondsOf(k), T_odom_body_[k]);
  EXPECT_TRUE(asked_.empty());
  EXPECT_TRUE(mapper.loopAttempts().empty());
  EXPECT_EQ(mapper.loopClosures(), 0u);
  EXPECT_LT(distanceM(mapper.graph().pose(159), T_odom_body_[159]), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// MappingThread against an inline Mapper, with the real verifier on a synthetic forest

// One and a half laps of a 40 m circle in a forest (keyframes 1 m and 1 s apart) whose odometry
// drifts 0.02 deg/m in heading with 0.3 % long steps; scans stored at the true poses.
class MappingOnAForest : public ::testing::Test {
 protected:
  MappingOnAForest() {
    config_.loop_exclude_recent_keyframes = 10;
    config_.loop_submap_keyframes = 3;
    const std::vector<lie::SE3> T_world_body_true = forest::circlePath(60);
    const std::vector<Eigen::Vector3d> forest_in_world = forest::forestInWorld(1);
    T_odom_body_.push_back(T_world_body_true.front());
    for (std::size_t k = 1; k < T_world_body_true.size(); ++k) {
      const lie::SE3 step = T_world_body_true[k - 1].inverse() * T_world_body_true[k];
      T_odom_body_.push_back(
          T_odom_body_.back() *
          lie::SE3(step.rotation() * lie::SO3::Exp(Eigen::Vector3d(0, 0, 0.02 * kRadPerDeg)),
                   step.translation() * 1.003));
    }
    for (std::size_t k = 0; k < T_world_body_true.size(); ++k)
      store_.add(secondsOf(k), T_odom_body_[k],
                 forest::scanInBody(forest_in_world, T_world_body_true[k],
                                    100 + static_cast<unsigned>(k)));
  }

  MappingConfig config_;
  const OdometryConfig odometry_;
  const taiga::test::TempDir dir_;
  KeyframeStore store_ =
      KeyframeStore::create(dir_.path(), {.registration_voxel_m = odometry_.voxel_size_m});
  std::vector<lie::SE3> T_odom_body_;
};

void expectSamePoses(const std::vector<lie::SE3>& a, const std::vector<lie::SE3>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].translation(), b[k].translation()) << k;
    EXPECT_EQ(a[k].rotation().quaternion().coeffs(), b[k].rotation().quaternion().coeffs()) << k;
  }
}

TEST_F(MappingOnAForest, TheThreadGivesTheInlineMapperResultBitForBit) {
  Mapper inline_mapper(config_, odometry_, store_);
  MappingThread thread(config_, odometry_, store_);
  for (std::size_t k = 0; k < T_odom_body_.size(); ++k) {
    inline_mapper.addKeyframe(k, secondsOf(k), T_odom_body_[k]);
    thread.addKeyframe(k, secondsOf(k), T_odom_body_[k]);
  }
  inline_mapper.finish();
  const Mapper& threaded = thread.finish();

  ASSERT_GE(inline_mapper.loopClosures(), 1u);  // the real verifier closed loops
  EXPECT_EQ(threaded.loopClosures(), inline_mapper.loopClosures());
  ASSERT_EQ(threaded.loopAttempts().size(), inline_mapper.loopAttempts().size());
  for (std::size_t i = 0; i < inline_mapper.loopAttempts().size(); ++i) {
    const LoopRecord& a = inline_mapper.loopAttempts()[i];
    const LoopRecord& b = threaded.loopAttempts()[i];
    EXPECT_EQ(a.attempt.current, b.attempt.current) << i;
    EXPECT_EQ(a.attempt.accepted, b.attempt.accepted) << i;
    EXPECT_EQ(a.chi2, b.chi2) << i;
  }
  expectSamePoses(threaded.graph().poses(), inline_mapper.graph().poses());
}

TEST_F(MappingOnAForest, EachSnapshotHoldsTheGraphsNewestPosesAfterItsKeyframe) {
  constexpr std::size_t kSnapshotKeyframes = 3;
  Mapper inline_mapper(config_, odometry_, store_);
  MappingThread thread(config_, odometry_, store_, {.snapshot_keyframes = kSnapshotKeyframes});
  bool a_loop_moved_the_newest_poses = false;
  for (std::size_t k = 0; k < T_odom_body_.size(); ++k) {
    inline_mapper.addKeyframe(k, secondsOf(k), T_odom_body_[k]);
    thread.addKeyframe(k, secondsOf(k), T_odom_body_[k]);
    const std::optional<GraphSnapshot> snapshot = thread.waitForSnapshot(k);
    ASSERT_TRUE(snapshot.has_value()) << k;
    EXPECT_EQ(snapshot->keyframe, k);
    const std::vector<lie::SE3>& poses = inline_mapper.graph().poses();
    const std::size_t count = std::min(kSnapshotKeyframes, poses.size());
    expectSamePoses(snapshot->poses_T_map_body,
                    std::vector<lie::SE3>(poses.end() - count, poses.end()));
    if (distanceM(snapshot->poses_T_map_body.back(), T_odom_body_[k]) > 0.05)
      a_loop_moved_the_newest_poses = true;
  }
  EXPECT_TRUE(a_loop_moved_the_newest_poses);
  thread.finish();
}

}  // namespace
}  // namespace taiga::mapping
