#pragma once
// Comma-separated numeric tables with a header row naming the columns. Internal to io.

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace taiga::io::detail {

class CsvTable {
 public:
  /// Opens `path` and reads its header row; InputError naming the file when it cannot.
  explicit CsvTable(const std::filesystem::path& path);

  /// Index of a column; InputError naming the file, the column and the header when absent.
  std::size_t require(const std::string& column) const;
  std::optional<std::size_t> find(const std::string& column) const;

  /// Reads the next data row into `values` (all numeric); false at the end. InputError with
  /// file, line and column name on a malformed value or a wrong number of values.
  bool next(std::vector<double>& values);
  /// InputError("PATH:LINE: message").
  [[noreturn]] void fail(const std::string& message) const;

 private:
  std::filesystem::path path_;
  std::ifstream stream_;
  std::vector<std::string> names_;
  int line_number_ = 0;
};

}  // namespace taiga::io::detail
