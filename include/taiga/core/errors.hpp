#pragma once
// Exceptions that carry a message meant for the user. Internal invariants use assert() instead.

#include <filesystem>
#include <stdexcept>
#include <string>

namespace taiga {

/// Bad input from a user: a file, a configuration or a command-line value. what() is the complete
/// message, naming the file, the line or field, and what was expected.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A query outside the domain of the data, e.g. a pose asked for outside a trajectory's span.
class OutOfRangeError : public std::out_of_range {
 public:
  using std::out_of_range::out_of_range;
};

/// The error for a file that could not be written or closed: names the file, the system's reason
/// (errno, e.g. "No space left on device") and the space left on its file system, so a full disk
/// is told apart from a damaged one. Call it right after the failed write, before errno changes.
InputError writeFailed(const std::filesystem::path& path);

}  // namespace taiga
