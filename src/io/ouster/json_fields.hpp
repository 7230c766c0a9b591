#pragma once
// Typed access to the fields of a JSON document with errors that name the source, the field's
// path and what was expected. Internal to the Ouster metadata reader.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "taiga/lie/se3.hpp"

namespace taiga::io::ouster::detail {

using Json = nlohmann::json;

/// A JSON object and the dotted path it was reached by ("" for the root).
struct JsonSection {
  const Json* object = nullptr;  ///< null when the section is absent
  std::string path;

  /// The member `key`, or null when the section or the member is absent or JSON null.
  const Json* find(std::string_view key) const;
  /// "path.key" (or "key" at the root), for messages.
  std::string name(std::string_view key) const;
};

class JsonFields {
 public:
  explicit JsonFields(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  /// Throws InputError("SOURCE: field 'FIELD': expected EXPECTED, found <description of found>").
  [[noreturn]] void fail(std::string_view field, std::string_view expected,
                         const Json* found) const;
  /// Throws InputError("SOURCE: MESSAGE").
  [[noreturn]] void failFile(std::string_view message) const;

  /// The member `key` of `section`; throws when it is absent.
  const Json& require(const JsonSection& section, std::string_view key,
                      std::string_view expected) const;

  double number(const Json& value, std::string_view field, std::string_view expected) const;
  /// An integer in [min, max] (a number with a fractional part is rejected).
  long long integer(const Json& value, std::string_view field, long long min, long long max) const;
  std::string string(const Json& value, std::string_view field, std::string_view expected) const;
  /// An array of finite numbers; `size` 0 accepts any non-empty length.
  std::vector<double> numbers(const Json& value, std::string_view field, std::string_view expected,
                              std::size_t size = 0) const;
  /// A 4x4 row-major homogeneous transform of 16 numbers with its translation in mm; returned
  /// with the translation in m. The rotation block must be a rotation (orthonormal, det +1).
  lie::SE3 transformMm(const Json& value, std::string_view field) const;

 private:
  std::string source_;
};

/// "a string \"abc\"", "an array of 3 values", "the number 5", ... for messages.
std::string describe(const Json* value);

}  // namespace taiga::io::ouster::detail
