// libFuzzer target for the binary files taiga reads back from its own runs: the keyframe store's
// .tkf files (mapping/keyframe_file.hpp) when the first byte is even, LAS headers and point
// records (io/las_reader.hpp) when it is odd. Any outcome but a crash, a sanitizer report or a
// hang is fine: bad input must end in an InputError.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "taiga/core/errors.hpp"
#include "taiga/io/las_reader.hpp"
#include "taiga/mapping/keyframe_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    if (data[0] % 2 == 0) {
      taiga::mapping::decodeKeyframe(bytes, "fuzz.tkf");
    } else {
      const taiga::io::LasHeader header = taiga::io::parseLasHeader(bytes, bytes.size(), "fuzz.las");
      taiga::PointCloud cloud;
      std::vector<std::uint16_t> ids;
      const std::string_view records = bytes.substr(
          header.point_data_offset,
          static_cast<std::size_t>(header.point_count) * header.record_length);
      taiga::io::decodeLasRecords(header, records, cloud, &ids);
    }
  } catch (const taiga::InputError&) {
  }
  return 0;
}
