#include "taiga/io/cloud_files.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lzf.h>

#include <cstring>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using test::messageOf;
using ::testing::HasSubstr;

const char* kPcdHeader =
    "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity t\nSIZE 4 4 4 "
    "4 4\n"
    "TYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n";

struct Record {
  float x, y, z, intensity;
  std::uint32_t t_ns;
};
const Record kRecords[3] = {{1.5f, 2.0f, -3.0f, 10.0f, 0},
                            {0.0f, 0.0f, 0.0f, 0.0f, 500},
                            {-4.25f, 8.0f, 0.5f, 7.0f, 1000000}};

std::string binaryBody() {
  return std::string(reinterpret_cast<const char*>(kRecords), sizeof kRecords);
}

// binary_compressed stores field after field: all x, then all y, ...
std::string compressedBody() {
  std::string fields_major;
  for (std::size_t f = 0; f < 5; ++f) {
    for (const Record& r : kRecords)
      fields_major.append(reinterpret_cast<const char*>(&r) + 4 * f, 4);
  }
  std::string compressed(fields_major.size() * 2 + 16, '\0');
  const unsigned n =
      lzf_compress(fields_major.data(), fields_major.size(), compressed.data(), compressed.size());
  const std::uint32_t sizes[2] = {n, static_cast<std::uint32_t>(fields_major.size())};
  return std::string(reinterpret_cast<const char*>(sizes), 8) + compressed.substr(0, n);
}

void expectTheThreeRecords(const DecodedPoints& d) {
  ASSERT_EQ(d.cloud.size(), 2u);  // the all-zero point is a missing return
  EXPECT_EQ(d.dropped_invalid, 1u);
  EXPECT_EQ(d.cloud.positions[0], Eigen::Vector3d(1.5, 2.0, -3.0));
  EXPECT_EQ(d.cloud.positions[1], Eigen::Vector3d(-4.25, 8.0, 0.5));
  EXPECT_EQ(d.cloud.intensities[1], 7.0f);
  EXPECT_DOUBLE_EQ(d.cloud.times_s[1], 100.001);
}

TEST(CloudFiles, ReadsPcdInAllThreeEncodings) {
  test::TempDir dir;
  const auto ascii =
      dir.write("a.pcd", std::string(kPcdHeader) +
                             "DATA ascii\n1.5 2 -3 10 0\n0 0 0 0 500\n-4.25 8 0.5 7 1000000\n");
  const auto binary = dir.write("b.pcd", std::string(kPcdHeader) + "DATA binary\n" + binaryBody());
  const auto compressed =
      dir.write("c.PCD", std::string(kPcdHeader) + "DATA binary_compressed\n" + compressedBody());
  for (const auto& path : {ascii, binary, compressed}) {
    SCOPED_TRACE(path.string());
    expectTheThreeRecords(readPointCloudFile(path, 100.0));
  }
}

TEST(CloudFiles, ReadsTheRealCloudComparePly) {
  const DecodedPoints d = readPointCloudFile("../shared/data/registration/source.ply", 0.0);
  // 69792 vertices, of which 5107 are (0, 0, 0): Velodyne's missing returns.
  EXPECT_EQ(d.cloud.size(), 69792u - 5107u);
  EXPECT_EQ(d.dropped_invalid, 5107u);
  EXPECT_TRUE(d.cloud.hasIntensities());  // CloudCompare's "scalar_intensity"
  for (const Eigen::Vector3d& p : d.cloud.positions) ASSERT_LT(p.norm(), 200.0);
}

TEST(CloudFiles, ReadsAsciiAndBigEndianPlyAndSkipsOtherElements) {
  test::TempDir dir;
  const auto ascii = dir.write(
      "a.ply",
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty double z\nproperty uchar ring\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n1 2 3 4\n5 6 7.5 8\n3 0 1 1\n");
  const DecodedPoints a = readPointCloudFile(ascii, 0.0);
  ASSERT_EQ(a.cloud.size(), 2u);
  EXPECT_EQ(a.cloud.positions[1], Eigen::Vector3d(5, 6, 7.5));
  EXPECT_EQ(a.cloud.rings[1], 8);

  // A face element before the vertices, and big-endian values.
  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  big += std::string("\x02\x00\x00\x00\x01\x00\x00\x00\x02", 9);  // face: 2 indices
  for (float v : {1.0f, -2.0f, 0.5f}) {
    std::uint8_t b[4];
    std::memcpy(b, &v, 4);
    big += std::string{char(b[3]), char(b[2]), char(b[1]), char(b[0])};
  }
  const DecodedPoints b = readPointCloudFile(dir.write("b.ply", big), 0.0);
  ASSERT_EQ(b.cloud.size(), 1u);
  EXPECT_EQ(b.cloud.positions[0], Eigen::Vector3d(1.0, -2.0, 0.5));
}

TEST(CloudFiles, WrittenPlyReadsBackBitExact) {
  test::TempDir dir;
  PointCloud cloud;
  cloud.positions = {{3385611.123456789, 6672118.4, 35.25}, {-0.1, 0.2, 0.3}};
  cloud.times_s = {1700000000.123456789, 1700000000.2};
  cloud.intensities = {12.5f, 0.0f};
  cloud.rings = {3, 127};
  writePly(dir.file("out.ply"), cloud);
  const DecodedPoints d = readPointCloudFile(dir.file("out.ply"), 0.0);
  ASSERT_EQ(d.cloud.size(), 2u);
  EXPECT_EQ(d.cloud.positions, cloud.positions);
  EXPECT_EQ(d.cloud.times_s, cloud.times_s);  // 'time' float64 is absolute here only by magnitude
  EXPECT_EQ(d.cloud.intensities, cloud.intensities);
  EXPECT_EQ(d.cloud.rings, cloud.rings);
}

struct BadFile {
  const char* name;
  std::string content;
  const char* message;
};

class CloudFilesReject : public ::testing::TestWithParam<BadFile> {};

TEST_P(CloudFilesReject, NamingFileAndProblem) {
  test::TempDir dir;
  const auto path = dir.write(GetParam().name, GetParam().content);
  const std::string message = messageOf<InputError>([&] { readPointCloudFile(path, 0.0); });
  EXPECT_THAT(message, HasSubstr(path.string() + ": "));
  EXPECT_THAT(message, HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, CloudFilesReject,
    ::testing::Values(
        BadFile{"trunc.pcd", std::string(kPcdHeader) + "DATA binary\n" + binaryBody().substr(0, 50),
                "truncated: 50 bytes of point data, 60 expected"},
        BadFile{"nodata.pcd", "VERSION 0.7\nFIELDS x y z\n", "the header ends without a DATA line"},
        BadFile{"sizes.pcd",
                "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
                "FIELDS lists 3 fields but SIZE 2 and TYPE 3"},
        BadFile{"type.pcd",
                "FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
                "TYPE F with SIZE 3 is not a PCD field type"},
        BadFile{"points.pcd",
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nPOINTS 3\nDATA ascii\n1 2 3\n",
                "POINTS 3 is not WIDTH 2 x HEIGHT 1"},
        BadFile{"word.pcd",
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 two 3\n",
                "point 0, field 'y': 'two' is not a number"},
        BadFile{"range.pcd",
                "FIELDS x y z r\nSIZE 4 4 4 1\nTYPE F F F U\nWIDTH 1\nPOINTS 1\nDATA ascii\n1 2 3 "
                "300\n",
                "point 0, field 'r': 300 does not fit uint8"},
        BadFile{
            "lines.pcd",
            "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n",
            "truncated"},
        BadFile{"huge.pcd",
                "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 4000000000\nDATA "
                "binary\n",
                "is not a plausible size"},
        BadFile{"lzf.pcd",
                std::string(kPcdHeader) + "DATA binary_compressed\n" +
                    std::string("\x10\x00\x00\x00\x3c\x00\x00\x00", 8) + std::string(16, '\xff'),
                "the compressed block is corrupt"},
        BadFile{"claim.pcd",
                std::string(kPcdHeader) + "DATA binary_compressed\n" +
                    std::string("\x10\x00\x00\x00\x00\x00\x00\x70", 8),
                "unpacks to"},
        BadFile{"encoding.pcd", std::string(kPcdHeader) + "DATA zip\n", "DATA 'zip' is not ascii"},
        BadFile{"notply.ply", "PLY\n", "does not start with 'ply'"},
        BadFile{"noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                "no end_header"},
        BadFile{"badtype.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n1\n",
                "'quad' is not a PLY property type"},
        BadFile{"list.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float "
                "x\nend_header\n1 1\n",
                "vertex property 'x' is a list"},
        BadFile{"short.ply",
                "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float "
                "x\nproperty float y\nproperty float z\nend_header\n" +
                    std::string(20, '\0'),
                "truncated: 5 vertices need 60 bytes, 20 present"},
        BadFile{"noxyz.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float a\nend_header\n1\n",
                "no x, y and z fields"},
        BadFile{"cloud.xyz", "1 2 3\n", "unknown point-cloud format '.xyz'"}));

}  // namespace
}  // namespace taiga::io

namespace taiga::io {
namespace {

TEST(CloudFiles, AsciiPlyEndingBeforeItsLastVertexIsAnError) {
  // Found by fuzz_cloud_files: the last vertex line ends the file before the vertex count is
  // reached, and the reader went past the end of the text.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float y\nproperty float "
      "\x84\nend_header\n0 2 3";
  try {
    parsePly(ply);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
}

TEST(CloudFiles, BinaryPlyElementWithoutPropertiesIsSkippedAtOnce) {
  // Found by fuzz_cloud_files: an element claiming 3e10 items and no properties was skipped one
  // empty item at a time (minutes); it takes no bytes, so it is skipped at once.
  const std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement junk 30000000000\nelement vertex 1\nproperty "
      "float x\nproperty float y\nproperty float z\nend_header\n" +
      std::string(12, '\0');
  const LoadedPoints loaded = parsePly(ply);
  EXPECT_EQ(loaded.packed.width, 1u);
}

}  // namespace
}  // namespace taiga::io
