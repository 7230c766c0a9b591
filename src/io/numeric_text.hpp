#pragma once
// Reading whitespace-separated numeric text files line by line, with errors that name the file
// and the line. Internal to the io module.

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace taiga::io::detail {

class NumericTextReader {
 public:
  /// Opens `path`; throws InputError("PATH: cannot open ...") when it cannot.
  explicit NumericTextReader(const std::filesystem::path& path);

  /// Reads the next line that is neither blank nor a '#' comment and parses all its values.
  /// Returns false at the end of the file. Throws InputError on a value that is not a finite
  /// number, naming the line and the value's position.
  bool next(std::vector<double>& values);

  /// Throws InputError("PATH:LINE: message") for the current line.
  [[noreturn]] void fail(const std::string& message) const;
  /// Throws InputError("PATH: message") for the file as a whole.
  [[noreturn]] void failFile(const std::string& message) const;

  int lineNumber() const { return line_number_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ifstream stream_;
  std::string line_;
  int line_number_ = 0;
};

/// The shortest text that reads back as exactly `value`.
std::string formatExact(double value);

/// The number written in `token` (a leading '+' allowed, "nan" and "inf" accepted), or nothing.
std::optional<double> parseDouble(std::string_view token);
/// parseDouble or InputError("CONTEXT: 'TOKEN' is not a number").
double parseNumber(std::string_view token, const std::string& context);
/// The words of `line` separated by spaces, tabs or carriage returns.
std::vector<std::string> splitWords(std::string_view line);
/// The whole content of a file; InputError naming the file when it cannot be read.
std::string readWholeFile(const std::filesystem::path& path);

}  // namespace taiga::io::detail
