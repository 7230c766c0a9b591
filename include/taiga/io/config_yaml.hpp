#pragma once
// YAML configuration files, read into and written from ConfigSections (core/config.hpp).
//
// A file overrides the values already in the config (its defaults, or a preset read before), at
// any depth: keys it does not mention keep their value. Every key in the file must be known:
// a typo is an error, never silently ignored. Errors are InputErrors of the form
//   "FILE:LINE:COLUMN: section.key: what was expected, what was found".

#include <filesystem>
#include <string>
#include <string_view>

#include "taiga/core/config.hpp"

namespace taiga::io {

/// Reads `path` into `config` and validates the result.
void readConfigYaml(const std::filesystem::path& path, ConfigSection& config);
/// Reads YAML text into `config`; `source_name` stands for the file name in messages.
void readConfigYamlText(std::string_view text, std::string_view source_name, ConfigSection& config);
/// The YAML text of `config`, with each field's documentation as a comment.
std::string writeConfigYaml(ConfigSection& config);

}  // namespace taiga::io
