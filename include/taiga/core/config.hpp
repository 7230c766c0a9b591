#pragma once
// The configuration mechanism shared by every module.
//
// Each module has one config struct deriving from ConfigSection. It lists its fields once, in
// visit(), with their key, unit and meaning, and checks their values in validate(). Readers and
// writers of configuration files (io/config_yaml.hpp) are ConfigVisitors: they walk that list,
// so a new field is parsed, rejected when mistyped, documented and written back without any
// further code. This header has no YAML dependency; parsing lives in io.

#include <Eigen/Core>
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include <vector>

#include "taiga/core/box.hpp"
#include "taiga/core/errors.hpp"
#include "taiga/lie/se3.hpp"

namespace taiga {

/// A configuration value that is out of range or inconsistent. `key` is the dotted path of the
/// field (relative to the section that threw; readers prefix the enclosing sections).
class ConfigError : public InputError {
 public:
  ConfigError(std::string key, const std::string& problem)
      : InputError(key + ": " + problem), key_(std::move(key)), problem_(problem) {}
  const std::string& key() const { return key_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string key_;
  std::string problem_;
};

class ConfigSection;

/// Something that walks the fields of a ConfigSection. `doc` states unit, frame and meaning.
class ConfigVisitor {
 public:
  virtual ~ConfigVisitor() = default;
  virtual void field(std::string_view key, double& value, std::string_view doc) = 0;
  virtual void field(std::string_view key, int& value, std::string_view doc) = 0;
  virtual void field(std::string_view key, bool& value, std::string_view doc) = 0;
  virtual void field(std::string_view key, std::string& value, std::string_view doc) = 0;
  virtual void field(std::string_view key, Eigen::Vector3d& value, std::string_view doc) = 0;
  /// A rigid transform T_a_b, written as translation_m plus quaternion_xyzw or rpy_deg.
  virtual void field(std::string_view key, lie::SE3& value, std::string_view doc) = 0;
  /// A list of axis-aligned boxes, each written as {min_m: [x, y, z], max_m: [x, y, z]}.
  virtual void field(std::string_view key, std::vector<Box>& value, std::string_view doc) = 0;
  /// A string restricted to `allowed` (an enumeration).
  virtual void choice(std::string_view key, std::string& value,
                      std::span<const std::string_view> allowed, std::string_view doc) = 0;
  virtual void section(std::string_view key, ConfigSection& value, std::string_view doc) = 0;
};

class ConfigSection {
 public:
  virtual ~ConfigSection() = default;
  /// Presents every field and subsection to the visitor, in the order they are documented.
  virtual void visit(ConfigVisitor& visitor) = 0;
  /// Throws ConfigError naming the key when a value of this section (not its subsections) is
  /// out of range or inconsistent.
  virtual void validate() const {}
};

/// A key that moved to another place (full dotted paths): readers say where it went instead of
/// calling it unknown.
struct MovedConfigKey {
  std::string_view old_key;
  std::string_view new_key;
  std::string_view why;
};
std::span<const MovedConfigKey> movedConfigKeys();

/// Validates `root` and all its subsections; the thrown ConfigError's key is the full dotted path.
void validateAll(ConfigSection& root);

/// Presents an enum field as a choice among names. `names` pairs each value with its name.
template <class Enum, std::size_t N>
void enumField(ConfigVisitor& visitor, std::string_view key, Enum& value,
               const std::array<std::pair<std::string_view, Enum>, N>& names,
               std::string_view doc) {
  std::array<std::string_view, N> allowed;
  std::string current;
  for (std::size_t i = 0; i < N; ++i) {
    allowed[i] = names[i].first;
    if (names[i].second == value) current = names[i].first;
  }
  visitor.choice(key, current, allowed, doc);
  for (const auto& [name, candidate] : names) {
    if (name == current) value = candidate;
  }
}

/// Checks used by validate(): each throws ConfigError(key, "expected ..., got ...").
void requireInRange(std::string_view key, double value, double min, double max,
                    std::string_view unit);
void requirePositive(std::string_view key, double value, std::string_view unit);
void requireNonNegative(std::string_view key, double value, std::string_view unit);

}  // namespace taiga
