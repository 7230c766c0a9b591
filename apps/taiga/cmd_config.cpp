// taiga config [FILE]: checks a configuration file and prints the effective configuration.
#include <fmt/format.h>

#include <memory>

#include "command.hpp"
#include "taiga/core/system_config.hpp"
#include "taiga/io/config_yaml.hpp"

namespace taiga::app {

Command addConfigCommand(CLI::App& tool) {
  auto file = std::make_shared<std::string>();
  CLI::App* parser = tool.add_subcommand(
      "config",
      "Check a configuration file and print the effective configuration (defaults overridden by "
      "FILE) as YAML with every key documented; without FILE, print the defaults");
  parser->add_option("FILE", *file, "YAML configuration file to check");
  return {parser,
          [file] {
            SystemConfig config;
            if (!file->empty()) io::readConfigYaml(*file, config);
            fmt::print("{}", io::writeConfigYaml(config));
            return static_cast<int>(kExitOk);
          },
          file};
}

}  // namespace taiga::app
