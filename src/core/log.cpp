#include "taiga/core/log.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace taiga {

spdlog::logger& logger() {
  static const std::shared_ptr<spdlog::logger> instance = [] {
    auto created = spdlog::stderr_color_mt("taiga");
    created->set_pattern("%^[%l]%$ %v");
    created->set_level(spdlog::level::info);
    return created;
  }();
  return *instance;
}

void setLogLevel(spdlog::level::level_enum level) { logger().set_level(level); }

}  // namespace taiga
