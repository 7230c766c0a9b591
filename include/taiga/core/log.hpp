#pragma once
// The one logger of the project. Library code reports through it and never prints directly.

#include <spdlog/logger.h>

namespace taiga {

/// The project logger ("taiga"), writing to standard error. Created on first use.
spdlog::logger& logger();

/// Sets the level below which messages are dropped (default: info).
void setLogLevel(spdlog::level::level_enum level);

}  // namespace taiga
