// libFuzzer target for the packed-point decoder as ROS PointCloud2 messages reach it: the input
// describes a field layout (as a driver, or a corrupt bag, could declare it) followed by the data.
//   byte 0: number of fields (mod 8); per field 4 bytes: name index, offset, datatype, count;
//   then width, height, point_step, row_step (u16 each), is_bigendian (1 byte), the rest is data.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "taiga/core/errors.hpp"
#include "taiga/io/point_fields.hpp"

namespace {

const char* kNames[] = {"x", "y", "z", "t", "time", "timestamp", "offset_time", "intensity", "reflectivity", "ring", "line", "other"};

class Input {
 public:
  Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(byte() | (byte() << 8)); }
  std::span<const std::uint8_t> rest() const { return {data_ + pos_, size_ - std::min(pos_, size_)}; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Input in(data, size);
  taiga::io::PackedPoints points;
  const int fields = in.byte() % 8;
  for (int i = 0; i < fields; ++i) {
    taiga::io::PointField f;
    f.name = kNames[in.byte() % (sizeof kNames / sizeof *kNames)];
    f.offset = in.byte();
    f.type = static_cast<taiga::io::FieldType>(in.byte() % 12);
    f.count = in.byte() % 4;
    points.fields.push_back(f);
  }
  points.width = in.u16();
  points.height = in.u16() % 64;
  points.point_step = in.u16();
  points.row_step = in.u16();
  points.is_bigendian = in.byte() & 1;
  points.data = in.rest();
  try {
    taiga::io::decodePackedPoints(points, 1700000000.0, {.scan_period_s = 0.1});
  } catch (const taiga::InputError&) {
  }
  return 0;
}
