#include "json_fields.hpp"

#include <fmt/format.h>

#include <cmath>

#include "taiga/core/errors.hpp"

namespace taiga::io::ouster::detail {
namespace {

// Rotation blocks in metadata are printed with a few digits (often exact 0/1/-1).
constexpr double kRotationTolerance = 1e-3;
constexpr std::size_t kQuoteLimit = 40;

}  // namespace

const Json* JsonSection::find(std::string_view key) const {
  if (object == nullptr || !object->is_object()) return nullptr;
  const auto it = object->find(key);
  if (it == object->end() || it->is_null()) return nullptr;
  return &*it;
}

std::string JsonSection::name(std::string_view key) const {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}

std::string describe(const Json* value) {
  if (value == nullptr) return "nothing (the field is missing)";
  switch (value->type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return fmt::format("the boolean {}", value->get<bool>());
    case Json::value_t::string: {
      std::string text = value->get<std::string>();
      if (text.size() > kQuoteLimit) text = text.substr(0, kQuoteLimit) + "...";
      return fmt::format("the string \"{}\"", text);
    }
    case Json::value_t::array:
      return fmt::format("an array of {} values", value->size());
    case Json::value_t::object:
      return "an object";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return fmt::format("the number {}", value->dump());
    default:
      return "a value of another type";
  }
}

void JsonFields::fail(std::string_view field, std::string_view expected, const Json* found) const {
  throw InputError(fmt::format("{}: field '{}': expected {}, found {}", source_, field, expected,
                               describe(found)));
}

void JsonFields::failFile(std::string_view message) const {
  throw InputError(fmt::format("{}: {}", source_, message));
}

const Json& JsonFields::require(const JsonSection& section, std::string_view key,
                                std::string_view expected) const {
  const Json* value = section.find(key);
  if (value == nullptr) fail(section.name(key), expected, nullptr);
  return *value;
}

double JsonFields::number(const Json& value, std::string_view field,
                          std::string_view expected) const {
  if (!value.is_number()) fail(field, expected, &value);
  const double result = value.get<double>();
  if (!std::isfinite(result)) fail(field, expected, &value);
  return result;
}

long long JsonFields::integer(const Json& value, std::string_view field, long long min,
                              long long max) const {
  const std::string expected = fmt::format("an integer in [{}, {}]", min, max);
  if (value.is_number_integer() || value.is_number_unsigned()) {
    // Unsigned values above the signed range are out of any range we accept.
    if (value.is_number_unsigned() && value.get<unsigned long long>() > 1ULL << 62)
      fail(field, expected, &value);
    const long long result = value.get<long long>();
    if (result < min || result > max) fail(field, expected, &value);
    return result;
  }
  fail(field, expected, &value);
}

std::string JsonFields::string(const Json& value, std::string_view field,
                               std::string_view expected) const {
  if (!value.is_string()) fail(field, expected, &value);
  return value.get<std::string>();
}

std::vector<double> JsonFields::numbers(const Json& value, std::string_view field,
                                        std::string_view expected, std::size_t size) const {
  if (!value.is_array() || value.empty() || (size != 0 && value.size() != size))
    fail(field, expected, &value);
  std::vector<double> result;
  result.reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    const Json& element = value[i];
    if (!element.is_number() || !std::isfinite(element.get<double>())) {
      fail(fmt::format("{}[{}]", field, i), "a finite number", &element);
    }
    result.push_back(element.get<double>());
  }
  return result;
}

lie::SE3 JsonFields::transformMm(const Json& value, std::string_view field) const {
  const std::vector<double> v =
      numbers(value, field, "16 numbers (a 4x4 row-major transform, translation in mm)", 16);
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = v[static_cast<std::size_t>(4 * r + c)];
  if (T(3, 0) != 0.0 || T(3, 1) != 0.0 || T(3, 2) != 0.0 || T(3, 3) != 1.0) {
    failFile(
        fmt::format("field '{}': expected a homogeneous transform whose last row is 0 0 0 1, "
                    "found {} {} {} {}",
                    field, T(3, 0), T(3, 1), T(3, 2), T(3, 3)));
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > kRotationTolerance || R.determinant() < 0.0) {
    failFile(
        fmt::format("field '{}': the 3x3 block is not a rotation (|R^T R - I| = {:.2g}, "
                    "det = {:.4f})",
                    field, error, R.determinant()));
  }
  T.topRightCorner<3, 1>() *= 1e-3;  // mm -> m
  return lie::SE3::fromMatrix(T);
}

}  // namespace taiga::io::ouster::detail
