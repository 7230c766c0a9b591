#include "taiga/io/folder_recording.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

std::string pcdWithTimes(int points) {
  std::string text = fmt::format("FIELDS x y z t\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH {}\nPOINTS {}\nDATA ascii\n", points, points);
  for (int i = 0; i < points; ++i) text += fmt::format("{} 1 0.5 {}\n", 2 + i, i * 10000000);  // 10 ms apart
  return text;
}

void makeFolder(const test::TempDir& dir) {
  std::filesystem::create_directories(dir.file("rec/scans"));
  dir.write("rec/scans/1700000000.0.pcd", pcdWithTimes(10));
  dir.write("rec/scans/1700000000100000000.pcd", pcdWithTimes(10));  // the same in ns
  std::string imu = "# a comment\nt_s, ax, ay, az, wx, wy, wz\n";
  for (int i = 0; i < 50; ++i) imu += fmt::format("{}, 0.1, 0, 9.8, 0, 0, 0.5\n", 1700000000.0 + 0.005 * i);
  dir.write("rec/imu.csv", imu);
  dir.write("rec/gnss.csv", "t_s,lat_deg,lon_deg,height_m,var_e_m2,var_n_m2,var_u_m2,status\n1700000000.1,60.1699,24.9384,35.5,0.5,0.5,2.0,2\n");
}

TEST(FolderRecording, MergesScansImuAndGnssInTimeOrder) {
  test::TempDir dir;
  makeFolder(dir);
  ASSERT_TRUE(isFolderRecording(dir.file("rec")));
  const auto files = listFolderScans(dir.file("rec"));
  ASSERT_EQ(files.size(), 2u);
  EXPECT_DOUBLE_EQ(files[1].stamp_s, 1700000000.1);

  Recording recording = openRecording(dir.file("rec"), {}, {});
  std::size_t scans = 0, imus = 0, fixes = 0;
  double previous = 0.0;
  while (auto event = recording.next()) {
    EXPECT_GE(eventTime(*event), previous);
    previous = eventTime(*event);
    if (const auto* scan = std::get_if<Scan>(&*event)) {
      EXPECT_EQ(scan->cloud_in_lidar.size(), 10u);
      EXPECT_NEAR(scan->t_end_s - scan->t_start_s, 0.09, 1e-6);
      EXPECT_NEAR(scan->t_start_s, 1700000000.0 + 0.1 * scans, 1e-6);
      ++scans;
    } else if (const auto* imu = std::get_if<ImuSample>(&*event)) {
      EXPECT_EQ(imu->angular_velocity_imu_radps.z(), 0.5);
      ++imus;
    } else {
      const GnssFix& fix = std::get<GnssFix>(*event);
      EXPECT_EQ(fix.status, GnssStatus::kGbasFix);
      EXPECT_EQ(fix.covariance_type, GnssCovarianceType::kDiagonalKnown);
      EXPECT_EQ(fix.covariance_enu_m2(2, 2), 2.0);
      ++fixes;
    }
  }
  EXPECT_EQ(scans, 2u);
  EXPECT_EQ(imus, 50u);
  EXPECT_EQ(fixes, 1u);
}

TEST(FolderRecording, BadInputNamesTheFileLineAndColumn) {
  test::TempDir dir;
  makeFolder(dir);
  const auto rec = dir.file("rec");
  auto readAll = [&] {
    Recording recording = openRecording(rec, {}, {});
    while (recording.next()) {
    }
  };

  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("imu.csv: no column 'wz' in the header (t_s,ax,ay,az,wx,wy)"));
  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy,wz\n1700000000,0,0,9.8,0,0,0\n1700000000.01,0,zero,9.8,0,0,0\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("imu.csv:3: column 'ay': 'zero' is not a number"));
  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy,wz\n1700000000,0,0,9.8,0,0\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("imu.csv:2: 6 values, the header names 7 columns"));
  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy,wz\n1700000000,0,0,nan,0,0,0\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("imu.csv:2: non-finite value"));
  dir.write("rec/imu.csv", "t_s,ax,ay,az,wx,wy,wz\n");

  dir.write("rec/gnss.csv", "t_s,lat_deg,lon_deg,height_m,status\n1700000000.1,60.1,24.9,35,7\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("gnss.csv:2: status must be -1, 0, 1 or 2"));
  dir.write("rec/gnss.csv", "t_s,lat_deg,lon_deg,height_m\n1700000000.1,6672118,24.9,35\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("gnss.csv:2: latitude 6672118"));
  std::filesystem::remove(dir.file("rec/gnss.csv"));

  dir.write("rec/scans/first.pcd", pcdWithTimes(1));
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("first.pcd: the file name must be the scan's start time"));
  std::filesystem::remove(dir.file("rec/scans/first.pcd"));
  dir.write("rec/scans/1700000000.1.pcd", pcdWithTimes(1));
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("have the same time"));
  std::filesystem::remove(dir.file("rec/scans/1700000000.1.pcd"));

  dir.write("rec/scans/1700000000.2.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA binary\n");
  EXPECT_THAT(messageOf<InputError>(readAll), HasSubstr("1700000000.2.pcd: truncated"));

  std::filesystem::create_directories(dir.file("empty"));
  EXPECT_THAT(messageOf<InputError>([&] { openRecording(dir.file("empty"), {}, {}); }),
              HasSubstr("a directory without scans/ or imu.csv is not a folder recording"));
  EXPECT_THAT(messageOf<InputError>([&] { openRecording(dir.write("x.mcap", ""), {}, {}); }),
              HasSubstr("x.mcap: not a recording taiga reads"));
  EXPECT_THAT(messageOf<InputError>([&] { openRecording(dir.file("nothing"), {}, {}); }), HasSubstr("no such file or directory"));
}

}  // namespace
}  // namespace taiga::io
