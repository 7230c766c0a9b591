#pragma once
// Reading whitespace-separated numeric text files line by line, with errors that name the file
// and the line. Internal to the io module.

#include <filesystem>
#include <fstream>
#include <string>
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

}  // namespace taiga::io::detail
