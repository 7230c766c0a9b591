// Registration without a trustworthy guess (yaw_search.hpp): the real HDL-32E pair with the
// source turned 30-60 deg about the vertical and registered from the identity, as `taiga
// register` does without --guess. Each answer is within 5 cm / 0.5 deg of the reference or
// reported as not converged, never a wrong pose marked converged; and a scene that is the same
// from two headings is reported as ambiguous.
#include "taiga/registration/yaw_search.hpp"

#include <gtest/gtest.h>

#include "registration_data.hpp"
#include "taiga/registration/voxel_means.hpp"
#include "taiga/registration/voxel_statistics.hpp"

namespace taiga::registration {
namespace {

lie::SE3 yawTurn(double deg) {
  return lie::SE3(lie::SO3::fromRollPitchYaw(0.0, 0.0, deg * kRadPerDeg), Eigen::Vector3d::Zero());
}

/// The real pair, the source voxelized as `taiga register` does, and NDT coarse to fine from 4 m.
struct RealPair {
  std::vector<Eigen::Vector3d> source =
      voxelDownsample(test::loadPositions(test::kRegistrationData / "source.ply"), 0.25);
  std::vector<Eigen::Vector3d> target = test::loadPositions(test::kRegistrationData / "target.ply");
  lie::SE3 reference = test::loadTransform(test::kRegistrationData / "T_target_source.txt");
  RegistrationConfig config = [] {
    RegistrationConfig c;
    c.ndt.coarse_resolutions_m = {4.0, 2.0};
    return c;
  }();

  /// The source turned by `turn`: its points are turn * p, so T_target_turned = T * turn^-1.
  std::vector<Eigen::Vector3d> turned(const lie::SE3& turn) const {
    std::vector<Eigen::Vector3d> points;
    for (const Eigen::Vector3d& p : source) points.push_back(turn * p);
    return points;
  }
};

TEST(YawSearch, TheRealPairTurnedThirtyToSixtyDegreesIsFoundOrReportedNeverWrong) {
  const RealPair pair;
  int found = 0;
  for (int k = 0; k < 20; ++k) {
    const double deg = (k % 2 ? -1.0 : 1.0) * (30.0 + 30.0 * k / 19.0);
    const lie::SE3 turn = yawTurn(deg);
    const YawSearchResult r =
        registerWithYawSearch(pair.turned(turn), pair.target, lie::SE3(), pair.config);
    const test::PoseError e =
        test::poseError(r.best.T_target_source, pair.reference * turn.inverse());
    const bool right = e.translation_m < 0.05 && e.rotation_deg < 0.5;
    EXPECT_TRUE(right || !r.best.converged)
        << deg << " deg: converged to a pose " << e.translation_m << " m / " << e.rotation_deg
        << " deg off";
    found += right && r.best.converged;
  }
  // Not by refusing everything: measured 20 of 20.
  EXPECT_GE(found, 18);
}

TEST(YawSearch, FromOneHeadingAFarTurnIsWrongThatIsWhyItSearches) {
  // The failure this guards against: a single start 60 deg off settles in a wrong basin.
  const RealPair pair;
  const lie::SE3 turn = yawTurn(60.0);
  const YawSearchResult one = registerWithYawSearch(pair.turned(turn), pair.target, lie::SE3(),
                                                    pair.config, {.hypotheses = 1});
  EXPECT_GT(test::poseError(one.best.T_target_source, pair.reference * turn.inverse()).rotation_deg,
            5.0);
}

TEST(YawSearch, ASceneTheSameFromTwoHeadingsIsAmbiguous) {
  // A long box corridor (two walls, floor, ceiling) with identical ends: turned by 180 deg it
  // looks the same, so two distinct solutions overlap equally.
  std::vector<Eigen::Vector3d> corridor;
  for (double x = -10.0; x <= 10.0; x += 0.1) {
    for (double s = -1.5; s <= 1.5; s += 0.1) {
      corridor.emplace_back(x, -1.5, s + 1.5);
      corridor.emplace_back(x, 1.5, s + 1.5);
      corridor.emplace_back(x, s, 0.0);
      corridor.emplace_back(x, s, 3.0);
    }
  }
  for (double y = -1.5; y <= 1.5; y += 0.1)
    for (double z = 0.0; z <= 3.0; z += 0.1) {
      corridor.emplace_back(-10.0, y, z);
      corridor.emplace_back(10.0, y, z);
    }
  RegistrationConfig config;
  config.ndt.coarse_resolutions_m = {4.0, 2.0};
  const YawSearchResult r = registerWithYawSearch(corridor, corridor, yawTurn(20.0), config);
  EXPECT_TRUE(r.ambiguous);
  EXPECT_FALSE(r.best.converged);
  EXPECT_NE(r.best.reason.find("ambiguous"), std::string::npos) << r.best.reason;
}

}  // namespace
}  // namespace taiga::registration
