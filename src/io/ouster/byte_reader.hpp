#pragma once
// Bounds-checked little-endian reads from a byte span. A read past the end returns 0 and marks the
// reader as failed, so a decoder fed arbitrary bytes can never read outside its buffer.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace taiga::io::ouster::detail {

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  /// The unsigned integer of sizeof(T) bytes (or `width` bytes, <= sizeof(T)) at `offset`.
  template <class T>
  T le(std::size_t offset, std::size_t width = sizeof(T)) {
    static_assert(std::is_unsigned_v<T>);
    if (width > sizeof(T) || offset > bytes_.size() || bytes_.size() - offset < width) {
      failed_ = true;
      return 0;
    }
    T value = 0;
    for (std::size_t i = 0; i < width; ++i)
      value |= static_cast<T>(static_cast<T>(bytes_[offset + i]) << (8 * i));
    return value;
  }

  float f32(std::size_t offset) { return std::bit_cast<float>(le<std::uint32_t>(offset)); }

  bool failed() const { return failed_; }
  std::size_t size() const { return bytes_.size(); }

 private:
  std::span<const std::uint8_t> bytes_;
  bool failed_ = false;
};

}  // namespace taiga::io::ouster::detail
