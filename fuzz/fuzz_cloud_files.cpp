// libFuzzer target for the point-cloud file parsers and the packed-point decoder behind them.
// The first byte picks PCD or PLY; the rest is the file. Any outcome but a crash, a sanitizer
// report or a hang is fine: bad input must end in an InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "taiga/core/errors.hpp"
#include "taiga/io/cloud_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const taiga::io::LoadedPoints loaded = data[0] % 2 == 0 ? taiga::io::parsePcd(bytes) : taiga::io::parsePly(bytes);
    taiga::io::decodePackedPoints(loaded.packed, 100.0);
  } catch (const taiga::InputError&) {
  }
  return 0;
}
