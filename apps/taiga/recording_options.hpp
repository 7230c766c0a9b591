#pragma once
// The configuration options shared by the subcommands that read a recording.

#include <CLI/CLI.hpp>
#include <string>

#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"

namespace taiga::app {

/// Adds --config FILE to `parser`, storing the path in `config_path`.
inline void addConfigOption(CLI::App& parser, std::string& config_path) {
  parser.add_option("--config", config_path, "YAML configuration: topics, clock offset, units (see `taiga config`)");
}

/// The defaults, overridden by `config_path` when given.
inline SystemConfig loadConfig(const std::string& config_path) {
  SystemConfig config;
  if (!config_path.empty()) io::readConfigYaml(config_path, config);
  return config;
}

}  // namespace taiga::app
