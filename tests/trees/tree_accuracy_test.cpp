#include "taiga/eval/tree_accuracy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace taiga::eval {
namespace {

trees::TreeRecord tree(long id, double x, double y, double dbh, double height = 20.0) {
  return {id, Eigen::Vector2d(x, y), 0.0, dbh, height};
}

TEST(TreeAccuracy, CountsDetectionsCommissionAndErrorsInTheReferenceFrame) {
  // Reference: 4 trees near a path along x (one too thin to count, one too far away).
  const std::vector<trees::TreeRecord> reference{tree(0, 0, 2, 0.20), tree(1, 5, -3, 0.30),
                                                 tree(2, 10, 1, 0.08), tree(3, 10, 40, 0.25),
                                                 tree(4, 15, 4, 0.40)};
  // Estimate in a frame shifted by (1, 0): two found (2 cm off, DBH +1 cm / -1 cm), the thin one
  // found, one missed, one false stem.
  const std::vector<trees::TreeRecord> estimate{tree(10, -1, 2.02, 0.21, 21.0),
                                                tree(11, 4, -3.02, 0.29, 19.0),
                                                tree(12, 9, 1, 0.09), tree(13, 0, -5, 0.3)};
  AlignmentTransform T;
  T.T_ref_est = lie::SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  const std::vector<Eigen::Vector3d> path{{-5, 0, 0}, {20, 0, 0}};
  const TreeAccuracy a = evaluateTrees(estimate, reference, T, path, {});
  EXPECT_EQ(a.reference, 3u);  // trees 0, 1, 4
  EXPECT_EQ(a.detected, 2u);
  EXPECT_NEAR(a.recall, 2.0 / 3.0, 1e-12);
  EXPECT_EQ(a.estimated, 4u);
  EXPECT_EQ(a.false_stems, 1u);  // the thin tree's stem is a match, not a false stem
  EXPECT_NEAR(a.commission, 0.25, 1e-12);
  EXPECT_NEAR(a.dbh_rmse_m, 0.01, 1e-9);
  EXPECT_NEAR(a.dbh_bias_m, 0.0, 1e-9);
  EXPECT_NEAR(a.position_rmse_m, 0.02, 1e-9);
  EXPECT_NEAR(a.height_rmse_m, 1.0, 1e-9);
  ASSERT_EQ(a.missed_ids.size(), 1u);
  EXPECT_EQ(a.missed_ids[0], 4);
  EXPECT_EQ(a.by_dbh[1].reference, 2u);  // 20-30 cm: trees 0 and 1
  EXPECT_EQ(a.by_dbh[1].detected, 2u);
  EXPECT_TRUE(std::isnan(a.dbh_within_2_sigma));  // no stem states a sigma
}

TEST(TreeAccuracy, CountsTheDbhErrorsWithinTwiceTheirStatedSigma) {
  const std::vector<trees::TreeRecord> reference{tree(0, 0, 2, 0.20), tree(1, 5, -3, 0.30),
                                                 tree(2, 10, 3, 0.25)};
  // DBH errors +1, -1 and +1 cm; stated sigmas 0.6 cm (within 2), 0.4 cm (not), none.
  std::vector<trees::TreeRecord> estimate{tree(10, 0, 2, 0.21), tree(11, 5, -3, 0.29),
                                          tree(12, 10, 3, 0.26)};
  estimate[0].dbh_sigma_m = 0.006;
  estimate[1].dbh_sigma_m = 0.004;
  estimate[2].dbh_sigma_m = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector3d> path{{-5, 0, 0}, {20, 0, 0}};
  const TreeAccuracy a = evaluateTrees(estimate, reference, AlignmentTransform{}, path, {});
  ASSERT_EQ(a.detected, 3u);
  EXPECT_NEAR(a.dbh_within_2_sigma, 0.5, 1e-12);  // of the two that state one
}

}  // namespace
}  // namespace taiga::eval
