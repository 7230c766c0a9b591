#include "taiga/io/point_fields.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

#include "../support/temp_dir.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

using ::testing::HasSubstr;
using test::messageOf;

// Packs records field by field, the way a driver fills a PointCloud2.
class Packer {
 public:
  explicit Packer(std::vector<PointField> fields, bool big_endian = false) : big_endian_(big_endian) {
    points_.fields = std::move(fields);
    for (const PointField& f : points_.fields) {
      points_.point_step = std::max<std::uint32_t>(points_.point_step, f.offset + fieldTypeSize(f.type));
    }
  }
  // Appends one point: values in field order.
  void add(std::initializer_list<double> values) {
    const std::size_t base = bytes_.size();
    bytes_.resize(base + points_.point_step, 0);
    auto v = values.begin();
    for (const PointField& f : points_.fields) write(bytes_.data() + base + f.offset, f.type, *v++);
  }
  PackedPoints finish(std::uint32_t height = 1) {
    points_.height = height;
    points_.width = static_cast<std::uint32_t>(bytes_.size() / points_.point_step / height);
    points_.row_step = points_.width * points_.point_step;
    points_.is_bigendian = big_endian_;
    points_.data = bytes_;
    return points_;
  }

 private:
  void write(std::uint8_t* p, FieldType type, double value) {
    packValue(p, type, value);
    if (big_endian_) std::reverse(p, p + fieldTypeSize(type));
  }
  PackedPoints points_;
  std::vector<std::uint8_t> bytes_;
  bool big_endian_;
};

using F = FieldType;

TEST(PointFields, OusterLayoutOrganizedWithNanosecondOffsets) {
  // ouster-ros: x y z intensity (float32), t (uint32 ns), reflectivity, ring (uint16); 2 rows.
  Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}, {"intensity", 16, F::kFloat32},
                 {"t", 20, F::kUint32}, {"reflectivity", 24, F::kUint16}, {"ring", 26, F::kUint16}});
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) {
      const bool missing = row == 1 && col == 1;  // no return: all zero
      packer.add({missing ? 0.0 : 1.0 + col, missing ? 0.0 : 2.0, missing ? 0.0 : 0.5, 900.0, col * 1e6, 40.0 + col, double(row)});
    }
  }
  const DecodedPoints d = decodePackedPoints(packer.finish(2), 1000.0);
  ASSERT_EQ(d.cloud.size(), 5u);
  EXPECT_EQ(d.dropped_invalid, 1u);
  EXPECT_EQ(d.time_source, PointTimeSource::kRelativeField);
  EXPECT_EQ(d.time_description, "field 't' (uint32, ns after the stamp)");
  EXPECT_DOUBLE_EQ(d.cloud.times_s[2], 1000.002);
  EXPECT_EQ(d.cloud.intensities[1], 41.0f);  // reflectivity is preferred over intensity
  EXPECT_EQ(d.cloud.rings[4], 1);
  EXPECT_EQ(d.cloud.columns[4], 2);
  EXPECT_EQ(d.cloud.positions[4], Eigen::Vector3d(3.0, 2.0, 0.5));
  EXPECT_TRUE(d.cloud.isConsistent());
}

TEST(PointFields, VelodyneRelativeSecondsAndBigEndian) {
  for (bool big_endian : {false, true}) {
    Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}, {"intensity", 12, F::kFloat32},
                   {"ring", 16, F::kUint16}, {"time", 18, F::kFloat32}},
                  big_endian);
    packer.add({1, 0, 0, 7, 3, -0.05});
    packer.add({0, 1, 0, 8, 4, 0.025});
    const DecodedPoints d = decodePackedPoints(packer.finish(), 50.0);
    ASSERT_EQ(d.cloud.size(), 2u) << big_endian;
    EXPECT_NEAR(d.cloud.times_s[0], 49.95, 1e-6);
    EXPECT_NEAR(d.cloud.times_s[1], 50.025, 1e-6);
    EXPECT_EQ(d.cloud.rings[1], 4);
    EXPECT_EQ(d.cloud.intensities[0], 7.0f);
    EXPECT_FALSE(d.cloud.hasColumns());
  }
}

// The positions are read by type-specific code for float32 and float64 in the machine's order,
// and by the general reader otherwise: every layout gives the same cloud.
TEST(PointFields, EveryPositionLayoutGivesTheSameCloud) {
  auto decoded = [](F x_type, F yz_type, bool big_endian) {
    const std::uint32_t x_size = fieldTypeSize(x_type), yz_size = fieldTypeSize(yz_type);
    Packer packer({{"x", 0, x_type},
                   {"y", x_size, yz_type},
                   {"z", x_size + yz_size, yz_type},
                   {"t", x_size + 2 * yz_size, F::kUint32},
                   {"ring", x_size + 2 * yz_size + 4, F::kUint16}},
                  big_endian);
    packer.add({1.5, -2.25, 0.5, 1e6, 3});
    packer.add({0.0, 0.0, 0.0, 2e6, 4});  // no return
    packer.add({-7.75, 12.125, -1.0, 3e6, 5});
    return decodePackedPoints(packer.finish(), 100.0);
  };
  const DecodedPoints reference = decoded(F::kFloat32, F::kFloat32, false);
  ASSERT_EQ(reference.cloud.size(), 2u);
  EXPECT_EQ(reference.cloud.positions[1], Eigen::Vector3d(-7.75, 12.125, -1.0));
  for (const auto& [x_type, yz_type] :
       {std::pair{F::kFloat64, F::kFloat64}, std::pair{F::kFloat64, F::kFloat32},
        std::pair{F::kFloat32, F::kFloat64}}) {
    for (const bool big_endian : {false, true}) {
      const DecodedPoints d = decoded(x_type, yz_type, big_endian);
      EXPECT_EQ(d.cloud.positions, reference.cloud.positions) << big_endian;
      EXPECT_EQ(d.cloud.times_s, reference.cloud.times_s) << big_endian;
      EXPECT_EQ(d.cloud.rings, reference.cloud.rings) << big_endian;
      EXPECT_EQ(d.dropped_invalid, 1u);
    }
  }
  EXPECT_EQ(decoded(F::kFloat32, F::kFloat32, true).cloud.positions, reference.cloud.positions);
}

TEST(PointFields, AbsoluteTimestampsInSecondsOrNanoseconds) {
  // Hesai: float64 seconds; Livox 2: float64 nanoseconds. Both absolute, whatever the stamp.
  for (double scale : {1.0, 1e9}) {
    Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}, {"timestamp", 16, F::kFloat64}});
    packer.add({1, 1, 1, 1700000000.25 * scale});
    const DecodedPoints d = decodePackedPoints(packer.finish(), 0.0);
    EXPECT_NEAR(d.cloud.times_s[0], 1700000000.25, 1e-6);
    EXPECT_EQ(d.time_source, PointTimeSource::kAbsoluteField);
    EXPECT_THAT(d.time_description, HasSubstr(scale == 1.0 ? "in s" : "in ns"));
  }
}

TEST(PointFields, LivoxOffsetTimeInNanoseconds) {
  Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}, {"offset_time", 12, F::kUint32},
                 {"line", 16, F::kUint8}});
  packer.add({5, 0, 0, 3e6, 2});
  const DecodedPoints d = decodePackedPoints(packer.finish(), 10.0);
  EXPECT_DOUBLE_EQ(d.cloud.times_s[0], 10.003);
  EXPECT_EQ(d.cloud.rings[0], 2);
}

TEST(PointFields, WithoutTimeFieldTimesFollowTheClockwiseAzimuth) {
  Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}});
  packer.add({1, 0, 0});   // azimuth 0: the start
  packer.add({0, -1, 0});  // -90 degrees: a quarter turn clockwise later
  packer.add({-1, 0, 0});  // 180 degrees: half a turn
  packer.add({0, 1, 0});   // +90 degrees: three quarters
  const DecodedPoints d = decodePackedPoints(packer.finish(), 2.0, {.scan_period_s = 0.1});
  EXPECT_EQ(d.time_source, PointTimeSource::kAzimuth);
  EXPECT_THAT(d.time_description, HasSubstr("no time field"));
  EXPECT_NEAR(d.cloud.times_s[0], 2.0, 1e-12);
  EXPECT_NEAR(d.cloud.times_s[1], 2.025, 1e-9);
  EXPECT_NEAR(d.cloud.times_s[2], 2.05, 1e-9);
  EXPECT_NEAR(d.cloud.times_s[3], 2.075, 1e-9);
}

// A flat cloud in firing order from a head whose beams fire at azimuths up to 9 deg apart (the
// OS0's stagger): the first column's points counter-clockwise of the first point belong to the
// sweep's start, not its end, and the last column's clockwise of it to its end.
TEST(PointFields, WithoutTimeFieldAStaggeredColumnStaysAtItsEndOfTheSweep) {
  constexpr int kColumns = 200;
  constexpr double kStagger_deg[4] = {3.05, 9.15, -3.05, -9.15};  // beam 1 is ahead of beam 0
  auto pack = [&](bool column_major) {
    Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}});
    for (int outer = 0; outer < (column_major ? kColumns : 4); ++outer)
      for (int inner = 0; inner < (column_major ? 4 : kColumns); ++inner) {
        const int column = column_major ? outer : inner, beam = column_major ? inner : outer;
        // Clockwise from azimuth 0 with time; beam 0 is the first point.
        const double az = (-360.0 * column / kColumns + kStagger_deg[beam] - kStagger_deg[0]) *
                          std::numbers::pi / 180.0;
        packer.add({static_cast<float>(std::cos(az)), static_cast<float>(std::sin(az)), 0.0f});
      }
    return decodePackedPoints(packer.finish(), 2.0, {.scan_period_s = 0.1}).cloud.times_s;
  };
  const std::vector<double> fired = pack(true);
  constexpr double kStaggerTime_s = 1.1 * 0.1 * 18.3 / 360.0;  // the widest stagger, as time
  for (int beam = 0; beam < 4; ++beam) {
    EXPECT_NEAR(fired[beam], 2.0, kStaggerTime_s) << beam;                          // column 0
    EXPECT_NEAR(fired[4 * (kColumns - 1) + beam], 2.1, kStaggerTime_s) << beam;  // the last
  }
  // Beam after beam the order says nothing of the time: the azimuth rule alone, so beam 1's
  // first column (counter-clockwise of the start) is taken for the sweep's end.
  const std::vector<double> by_beam = pack(false);
  EXPECT_NEAR(by_beam[kColumns], 2.1, kStaggerTime_s);
}

TEST(PointFields, OrganizedWithoutTimeFieldUsesTheColumn) {
  Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}});
  for (int i = 0; i < 8; ++i) packer.add({1, 1, 1});
  const DecodedPoints d = decodePackedPoints(packer.finish(2), 0.0, {.scan_period_s = 0.1});
  EXPECT_EQ(d.time_source, PointTimeSource::kColumnIndex);
  EXPECT_NEAR(d.cloud.times_s[3], 0.075, 1e-12);  // column 3 of 4
  EXPECT_EQ(d.cloud.rings[5], 1);                  // the row stands for the ring
}

TEST(PointFields, DropsNonFinitePoints) {
  Packer packer({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}});
  packer.add({std::nan(""), 1, 1});
  packer.add({1, INFINITY, 1});
  packer.add({1, 1, 1});
  const DecodedPoints d = decodePackedPoints(packer.finish(), 0.0);
  EXPECT_EQ(d.cloud.size(), 1u);
  EXPECT_EQ(d.dropped_invalid, 2u);
}

TEST(PointFields, RejectsInconsistentLayouts) {
  Packer good({{"x", 0, F::kFloat32}, {"y", 4, F::kFloat32}, {"z", 8, F::kFloat32}});
  good.add({1, 2, 3});
  good.add({1, 2, 3});
  const PackedPoints base = good.finish();

  PackedPoints outside = base;
  outside.fields.push_back({"t", 10, F::kUint32});
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(outside, 0); }),
              HasSubstr("field 't' (offset 10, 1 x uint32) does not fit in point_step 12"));

  PackedPoints short_data = base;
  short_data.width = 3;
  short_data.row_step = 36;
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(short_data, 0); }),
              HasSubstr("data holds 24 bytes but 1 x 3 points of 12 bytes need 36"));

  PackedPoints narrow_rows = base;
  narrow_rows.row_step = 12;
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(narrow_rows, 0); }), HasSubstr("row_step 12 is smaller"));

  PackedPoints no_z = base;
  no_z.fields.pop_back();
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(no_z, 0); }), HasSubstr("no x, y and z fields (fields: x:float32 y:float32)"));

  PackedPoints integer_x = base;
  integer_x.fields[0].type = F::kInt32;
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(integer_x, 0); }), HasSubstr("field 'x' is int32"));

  PackedPoints bad_type = base;
  bad_type.fields[1].type = static_cast<FieldType>(42);
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(bad_type, 0); }), HasSubstr("unknown datatype 42"));

  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(base, 0, {.time_field = "stamp"}); }),
              HasSubstr("the configured time field 'stamp' is not among the fields"));

  PackedPoints zero_step = base;
  zero_step.point_step = 0;
  EXPECT_THAT(messageOf<InputError>([&] { decodePackedPoints(zero_step, 0); }), HasSubstr("point_step is 0"));
}

}  // namespace
}  // namespace taiga::io
