#include "numeric_text.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>

#include "taiga/core/errors.hpp"

namespace taiga::io::detail {
namespace {

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

}  // namespace

NumericTextReader::NumericTextReader(const std::filesystem::path& path) : path_(path) {
  if (std::filesystem::is_directory(path)) failFile("is a directory, expected a text file");
  stream_.open(path);
  if (!stream_) failFile(fmt::format("cannot open: {}", std::strerror(errno)));
}

bool NumericTextReader::next(std::vector<double>& values) {
  while (std::getline(stream_, line_)) {
    ++line_number_;
    std::size_t pos = 0;
    while (pos < line_.size() && isSpace(line_[pos])) ++pos;
    if (pos == line_.size() || line_[pos] == '#') continue;

    values.clear();
    while (pos < line_.size()) {
      std::size_t end = pos;
      while (end < line_.size() && !isSpace(line_[end])) ++end;
      const char* first = line_.data() + pos;
      const char* last = line_.data() + end;
      const std::string token(first, last);
      if (*first == '+' && last - first > 1) ++first;  // from_chars rejects an explicit '+'
      double value = 0.0;
      const auto [ptr, ec] = std::from_chars(first, last, value);
      if (ec == std::errc::result_out_of_range) {
        fail(
            fmt::format("value {} '{}' is out of the range of a double", values.size() + 1, token));
      }
      if (ec != std::errc() || ptr != last) {
        if (token.find(',') != std::string::npos) {
          fail(fmt::format("value {} '{}' contains a comma; values must be separated by spaces",
                           values.size() + 1, token));
        }
        fail(fmt::format("value {} '{}' is not a number", values.size() + 1, token));
      }
      if (!std::isfinite(value)) {
        fail(fmt::format("value {} '{}' is not a finite number", values.size() + 1, token));
      }
      values.push_back(value);
      pos = end;
      while (pos < line_.size() && isSpace(line_[pos])) ++pos;
    }
    return true;
  }
  if (stream_.bad()) failFile("read error");
  return false;
}

void NumericTextReader::fail(const std::string& message) const {
  throw InputError(fmt::format("{}:{}: {}", path_.string(), line_number_, message));
}

void NumericTextReader::failFile(const std::string& message) const {
  throw InputError(fmt::format("{}: {}", path_.string(), message));
}

std::string formatExact(double value) { return fmt::format("{}", value); }

std::optional<double> parseDouble(std::string_view token) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+' && last - first > 1) ++first;  // from_chars rejects '+'
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(first, last, value);
  // Out of range (1e999) is not a number we can use either.
  if (ec != std::errc() || ptr != last || first == last) return std::nullopt;
  return value;
}

double parseNumber(std::string_view token, const std::string& context) {
  if (auto value = parseDouble(token)) return *value;
  throw InputError(fmt::format("{}: '{}' is not a number", context, token));
}

std::vector<std::string> splitWords(std::string_view line) {
  std::vector<std::string> words;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && isSpace(line[pos])) ++pos;
    std::size_t end = pos;
    while (end < line.size() && !isSpace(line[end])) ++end;
    if (end > pos) words.emplace_back(line.substr(pos, end - pos));
    pos = end;
  }
  return words;
}

std::string readWholeFile(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(fmt::format("{}: {}", path.string(), std::filesystem::exists(path) ? "is not a regular file" : "no such file"));
  }
  std::ifstream stream(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  if (stream.bad()) throw InputError(fmt::format("{}: read error", path.string()));
  return text;
}

}  // namespace taiga::io::detail
