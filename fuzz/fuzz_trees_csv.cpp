// libFuzzer target for tree lists (trees.csv, trees/tree_files.hpp), which `taiga eval --trees`
// reads from users and from the simulator. Any outcome but a crash, a sanitizer report or a hang
// is fine: bad input must end in an InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "taiga/core/errors.hpp"
#include "taiga/trees/tree_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    taiga::trees::parseTreesCsv(std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv");
  } catch (const taiga::InputError&) {
  }
  return 0;
}
