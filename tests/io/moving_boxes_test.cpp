#include "taiga/io/moving_boxes.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;

constexpr const char* kHeader = "scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n";

std::filesystem::path write(const test::TempDir& dir, const std::string& text) {
  const auto path = dir.path() / "boxes.csv";
  std::ofstream(path) << text;
  return path;
}

TEST(MovingBoxes, ReadsBoxesAndHandsThemToTheScanWhoseSpanHoldsTheStamp) {
  test::TempDir dir;
  // A box 2 m long along the body's y axis after a 90 deg yaw (qw = qz = sqrt(1/2)).
  const auto path = write(dir, std::string("# boom of a harvester\n") + kHeader +
                                   "100.0,1,3,0,1,1,0.2,0.2,0.70710678,0,0,0.70710678\n"
                                   "100.0,2,0,0,-1,0.5,0.5,0.5,1,0,0,0\n"
                                   "\n"
                                   "100.1,1,5,0,1,1,0.2,0.2,1,0,0,0\n");
  const MovingBoxes boxes = readMovingBoxes(path);
  EXPECT_EQ(boxes.stamps(), 2u);
  const auto first = boxes.forScan(100.0, 100.0999);
  ASSERT_EQ(first.size(), 2u);
  EXPECT_TRUE(first[0].contains({3.0, 0.9, 1.0}));   // along the rotated long axis
  EXPECT_FALSE(first[0].contains({3.9, 0.0, 1.0}));  // along the short one
  EXPECT_TRUE(first[1].contains({0.4, -0.4, -0.6}));
  // The scan's first point may come a little after its stamp, not before.
  EXPECT_EQ(boxes.forScan(100.0004, 100.0999).size(), 2u);
  EXPECT_EQ(boxes.forScan(100.1, 100.1999).size(), 1u);
  EXPECT_EQ(boxes.forScan(99.9, 99.9999).size(), 0u);
  EXPECT_EQ(boxes.forScan(100.2, 100.2999).size(), 0u);
}

TEST(MovingBoxes, ExpressedInAnotherFrameContainsTheSamePoints) {
  const OrientedBox box_body{{1, 2, 3}, {0.5, 0.2, 0.1}, lie::SO3::fromRollPitchYaw(0.1, 0.2, 0.3).matrix()};
  const lie::SE3 T_lidar_body(lie::SO3::fromRollPitchYaw(0.0, 0.0, 3.0), {0.1, -0.2, 0.3});
  const OrientedBox box_lidar = box_body.expressedIn(T_lidar_body);
  for (const Eigen::Vector3d& p_body :
       {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(1.3, 2.1, 3.05), Eigen::Vector3d(1.6, 2, 3),
        Eigen::Vector3d(1, 2.3, 3)}) {
    EXPECT_EQ(box_body.contains(p_body), box_lidar.contains(T_lidar_body * p_body))
        << p_body.transpose();
  }
}

struct BadBoxes {
  const char* text;
  const char* message;
};
class MovingBoxesRejects : public ::testing::TestWithParam<BadBoxes> {};

TEST_P(MovingBoxesRejects, NamingFileLineAndColumn) {
  test::TempDir dir;
  const auto path = write(dir, GetParam().text);
  try {
    readMovingBoxes(path);
    FAIL() << "accepted " << GetParam().text;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string()));
    EXPECT_THAT(e.what(), HasSubstr(GetParam().message));
  }
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, MovingBoxesRejects,
    ::testing::Values(
        BadBoxes{"", "empty; expected the header"},
        BadBoxes{"t,id,cx\n", ":1: expected the header 'scan_stamp_s,box_id"},
        BadBoxes{"scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n1,2,3\n",
                 ":2: expected 12 values"},
        BadBoxes{"scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n1,1,0,0,zero,1,1,1,1,0,0,0\n",
                 ":2: cz: 'zero' is not a finite number"},
        BadBoxes{"scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n1,1,0,0,0,1,nan,1,1,0,0,0\n",
                 ":2: hy: 'nan' is not a finite number"},
        BadBoxes{"scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n1,1,0,0,0,1,-1,1,1,0,0,0\n",
                 ":2: hx, hy, hz: half extents must not be negative"},
        BadBoxes{"scan_stamp_s,box_id,cx,cy,cz,hx,hy,hz,qw,qx,qy,qz\n1,1,0,0,0,1,1,1,0,0,0,0\n",
                 ":2: qw, qx, qy, qz = (0, 0, 0, 0) has norm 0.0000"}));

TEST(MovingBoxes, MissingFileIsNamed) {
  EXPECT_THROW(readMovingBoxes("/nonexistent/boxes.csv"), InputError);
}

}  // namespace
}  // namespace taiga::io
