// LAS output checked twice: field by field against the specification's layout, and by an
// independent reader (copc.js, run with Node.js from tools/las-check) that shares no code with taiga.
#include "taiga/io/las_writer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

const char* kWkt =
    "PROJCS[\"ETRS89 / TM35FIN(E,N)\",GEOGCS[\"ETRS89\",DATUM[\"European_Terrestrial_Reference_System_1989\","
    "SPHEROID[\"GRS 1980\",6378137,298.257222101]],PRIMEM[\"Greenwich\",0],UNIT[\"degree\",0.0174532925199433]],"
    "PROJECTION[\"Transverse_Mercator\"],PARAMETER[\"central_meridian\",27],PARAMETER[\"scale_factor\",0.9996],"
    "PARAMETER[\"false_easting\",500000],UNIT[\"metre\",1],AUTHORITY[\"EPSG\",\"3067\"]]";

// Projected coordinates (Helsinki in ETRS-TM35FIN) with sub-millimetre parts.
PointCloud helsinkiCloud(int n, double t0) {
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    cloud.positions.emplace_back(385611.3 + 0.0101 * i, 6672118.4 - 0.0203 * i, 35.25 + 0.001 * i);
    cloud.times_s.push_back(t0 + 0.001 * i);
    cloud.intensities.push_back(float(i % 300));
    cloud.rings.push_back(static_cast<std::uint16_t>(i % 128));
  }
  return cloud;
}

nlohmann::json readWithCopc(const std::filesystem::path& las, int max_points) {
  const std::string command = "node tools/las-check/las-check.mjs " + las.string() + " " + std::to_string(max_points) + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  std::array<char, 4096> buffer;
  while (pipe && std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int status = pipe ? pclose(pipe) : -1;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "las-check failed (run scripts/setup.sh):\n" << output;
  return nlohmann::json::parse(output, nullptr, false);
}

TEST(LasWriter, IndependentReaderSeesWhatWasWritten) {
  test::TempDir dir;
  const auto path = dir.file("map.las");
  {
    LasOptions options;
    options.wkt = kWkt;
    LasWriter writer(path, options);
    writer.append(helsinkiCloud(500, 1700000000.0), 7);
    writer.append(helsinkiCloud(300, 1700000100.0), 8);  // streamed in chunks
    writer.close();
    EXPECT_EQ(writer.pointCount(), 800u);
    EXPECT_EQ(writer.offset(), Eigen::Vector3d(385000, 6672000, 0));
  }
  const nlohmann::json las = readWithCopc(path, 800);
  ASSERT_FALSE(las.is_discarded());
  EXPECT_EQ(las["version"], "1.4");
  EXPECT_EQ(las["pointDataRecordFormat"], 6);
  EXPECT_EQ(las["pointCount"], 800);
  EXPECT_EQ(las["globalEncoding"].get<int>() & 16, 16);  // WKT
  ASSERT_EQ(las["vlrs"].size(), 1u);
  EXPECT_EQ(las["vlrs"][0]["wkt"], kWkt);

  const PointCloud first = helsinkiCloud(500, 1700000000.0), second = helsinkiCloud(300, 1700000100.0);
  for (int i = 0; i < 800; ++i) {
    const PointCloud& cloud = i < 500 ? first : second;
    const int k = i < 500 ? i : i - 500;
    const nlohmann::json& p = las["points"][i];
    for (int axis = 0; axis < 3; ++axis) {
      // Millimetre resolution: within half a millimetre of the true coordinate.
      EXPECT_NEAR(p[std::string(1, char('X' + axis))].get<double>(), cloud.positions[k][axis], 0.0005 + 1e-9);
    }
    EXPECT_EQ(p["GpsTime"].get<double>(), cloud.times_s[k]);
    EXPECT_EQ(p["Intensity"].get<int>(), static_cast<int>(cloud.intensities[k]));
    EXPECT_EQ(p["UserData"].get<int>(), cloud.rings[k]);
    EXPECT_EQ(p["PointSourceId"].get<int>(), i < 500 ? 7 : 8);
    EXPECT_EQ(p["ReturnNumber"].get<int>(), 1);
    EXPECT_EQ(p["NumberOfReturns"].get<int>(), 1);
    EXPECT_EQ(p["Classification"].get<int>(), 1);
  }
  // Header bounds are those of the stored (millimetre) coordinates.
  EXPECT_NEAR(las["min"][0].get<double>(), 385611.3, 1e-6);
  EXPECT_NEAR(las["max"][2].get<double>(), 35.25 + 0.499, 1e-6);
}

TEST(LasWriter, LocalCoordinatesWithoutCoordinateSystem) {
  test::TempDir dir;
  PointCloud cloud;
  cloud.positions = {{-12.3456, 7.0, 0.5}, {3.0, -4.0, 25.0}};
  {
    LasWriter writer(dir.file("local.las"));
    writer.append(cloud);
  }
  const nlohmann::json las = readWithCopc(dir.file("local.las"), 2);
  ASSERT_FALSE(las.is_discarded());
  EXPECT_TRUE(las["vlrs"].empty());
  EXPECT_EQ(las["pointCount"], 2);
  EXPECT_NEAR(las["points"][0]["X"].get<double>(), -12.346, 1e-9);  // -12.3456 rounds to -12.346
  EXPECT_EQ(las["offset"][0], -1000.0);
}

TEST(LasWriter, RejectsCoordinatesBeyondTheIntegerRange) {
  test::TempDir dir;
  LasOptions options;
  options.offset_m = Eigen::Vector3d::Zero();
  LasWriter writer(dir.file("far.las"), options);
  PointCloud cloud;
  cloud.positions = {{6672118.4, 0.0, 0.0}};  // 6.7e9 mm does not fit 32 bits around 0
  EXPECT_THAT(messageOf<InputError>([&] { writer.append(cloud); }),
              HasSubstr("coordinate 6672118.4 m does not fit LAS's 32-bit range at scale 0.001 m around offset 0 m"));
  EXPECT_THAT(messageOf<InputError>([&] { LasWriter(dir.file("missing/dir/x.las")); }), HasSubstr("cannot open for writing"));
}

// A full disk (Linux's /dev/full fails every write with ENOSPC) is named as such, with the file.
TEST(LasWriter, AFullDiskIsSaidWithTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  LasWriter writer("/dev/full");
  const std::string message = messageOf<InputError>([&] {
    writer.append(helsinkiCloud(200000, 0.0));  // 7 MB: more than the stream's buffer
    writer.close();
  });
  EXPECT_THAT(message, HasSubstr("/dev/full: write failed: No space left on device"));
}

}  // namespace
}  // namespace taiga::io

namespace taiga::io {
namespace {

// Airborne lidar's returns (sim/als.hpp): each point's return byte, and the header's points by
// return (15 counts at byte 255 of a LAS 1.4 header).
TEST(LasWriter, WritesReturnNumbersAndCountsThemInTheHeader) {
  test::TempDir dir;
  PointCloud cloud;
  cloud.positions = {{1.0, 2.0, 30.0}, {1.0, 2.0, 10.0}, {5.0, 6.0, 10.0}};
  const std::vector<std::uint8_t> classes = {1, 2, 2};
  const std::vector<std::uint16_t> ids(3, 0);
  const std::vector<std::array<std::uint8_t, 2>> returns = {{1, 2}, {2, 2}, {1, 1}};
  const auto path = dir.file("returns.las");
  {
    LasWriter writer(path);
    writer.append(cloud, {.classifications = classes, .source_ids = ids, .returns = returns});
    writer.close();
  }
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::uint64_t by_return[15];
  std::memcpy(by_return, bytes.data() + 255, sizeof(by_return));
  EXPECT_EQ(by_return[0], 2u);
  EXPECT_EQ(by_return[1], 1u);
  std::uint32_t offset = 0;
  std::memcpy(&offset, bytes.data() + 96, 4);
  EXPECT_EQ(static_cast<std::uint8_t>(bytes[offset + 14]), 0x21);       // 1 of 2
  EXPECT_EQ(static_cast<std::uint8_t>(bytes[offset + 30 + 14]), 0x22);  // 2 of 2
  EXPECT_EQ(static_cast<std::uint8_t>(bytes[offset + 60 + 14]), 0x11);  // 1 of 1
  EXPECT_EQ(bytes[offset + 30 + 16], 2);                                // ground

  LasWriter bad(dir.file("bad.las"));
  const std::vector<std::array<std::uint8_t, 2>> third_of_two = {{3, 2}, {1, 1}, {1, 1}};
  EXPECT_THROW(bad.append(cloud, {.returns = third_of_two}), std::logic_error);
}

}  // namespace
}  // namespace taiga::io
