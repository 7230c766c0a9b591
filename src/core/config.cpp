#include "taiga/core/config.hpp"

#include <fmt/format.h>

#include <cmath>

namespace taiga {
namespace {

// Walks the section tree and validates every section, prefixing the key of a thrown ConfigError
// with the path of the section it came from.
class ValidatingVisitor final : public ConfigVisitor {
 public:
  void field(std::string_view, double&, std::string_view) override {}
  void field(std::string_view, int&, std::string_view) override {}
  void field(std::string_view, bool&, std::string_view) override {}
  void field(std::string_view, std::string&, std::string_view) override {}
  void field(std::string_view, Eigen::Vector3d&, std::string_view) override {}
  void field(std::string_view, lie::SE3&, std::string_view) override {}
  void field(std::string_view, std::vector<Box>&, std::string_view) override {}
  void choice(std::string_view, std::string&, std::span<const std::string_view>,
              std::string_view) override {}
  void section(std::string_view key, ConfigSection& value, std::string_view) override {
    try {
      validateAll(value);
    } catch (const ConfigError& e) {
      throw ConfigError(std::string(key) + "." + e.key(), e.problem());
    }
  }
};

std::string withUnit(double value, std::string_view unit) {
  return unit.empty() ? fmt::format("{}", value) : fmt::format("{} {}", value, unit);
}

}  // namespace

std::span<const MovedConfigKey> movedConfigKeys() {
  // Issue 23: the GNSS fusion and the post-fit georeferencing had a setting each for the same
  // receiver; one is kept.
  static constexpr MovedConfigKey kMoved[] = {
      {"mapping.gnss_max_horizontal_sigma_m", "georef.max_horizontal_sigma_m",
       "one gate for the GNSS fusion and the georeferencing"},
      {"mapping.gnss_correlation_time_s", "georef.error_correlation_time_s",
       "one GNSS error model for the fusion and the georeferencing"},
  };
  return kMoved;
}

void validateAll(ConfigSection& root) {
  root.validate();
  ValidatingVisitor visitor;
  root.visit(visitor);
}

void requireInRange(std::string_view key, double value, double min, double max,
                    std::string_view unit) {
  if (!(value >= min && value <= max)) {  // also rejects NaN
    throw ConfigError(std::string(key), fmt::format("expected a value in [{}, {}]{}{}, got {}", min,
                                                    max, unit.empty() ? "" : " ", unit, value));
  }
}

void requirePositive(std::string_view key, double value, std::string_view unit) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw ConfigError(std::string(key),
                      fmt::format("expected a positive value, got {}", withUnit(value, unit)));
  }
}

void requireNonNegative(std::string_view key, double value, std::string_view unit) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    throw ConfigError(std::string(key),
                      fmt::format("expected a value >= 0, got {}", withUnit(value, unit)));
  }
}

}  // namespace taiga
