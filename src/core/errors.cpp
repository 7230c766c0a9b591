#include "taiga/core/errors.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>

namespace taiga {

InputError writeFailed(const std::filesystem::path& path) {
  const int error = errno;
  const std::string reason = error != 0 ? std::strerror(error) : "reason unknown";
  std::error_code ec;
  const auto parent = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const std::filesystem::space_info space = std::filesystem::space(parent, ec);
  const std::string free_space = ec ? std::string()
                                    : fmt::format(" ({:.2f} GB free on its file system)",
                                                  static_cast<double>(space.available) / 1e9);
  return InputError(fmt::format("{}: write failed: {}{}", path.string(), reason, free_space));
}

}  // namespace taiga
