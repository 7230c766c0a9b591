#pragma once
// Exceptions that carry a message meant for the user. Internal invariants use assert() instead.

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

}  // namespace taiga
