#pragma once
/// \file byte_codec.h
/// The byte encoding of every binary part of a model folder (docs/model-format.md): integers
/// and IEEE-754 floats little-endian, whatever the host's byte order.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {

namespace byte_codec_detail {
/// The unsigned integer of T's size, whose shifts give T's bytes in order.
template <class T>
using UnsignedOf =
    std::conditional_t<sizeof(T) == 1, std::uint8_t,
                       std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                          std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
}  // namespace byte_codec_detail

/// Appends values little-endian.
class ByteWriter {
 public:
  /// Starts with `prefix` (e.g. a magic string's bytes).
  explicit ByteWriter(std::vector<std::uint8_t> prefix = {}) : bytes_(std::move(prefix)) {}

  /// \pre T is an arithmetic type of at most 8 bytes.
  template <class T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T> && sizeof(T) <= 8, "only numbers have a byte encoding");
    byte_codec_detail::UnsignedOf<T> bits;
    std::memcpy(&bits, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  }

  const std::vector<std::uint8_t>& bytes() const { return bytes_; }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

/// Reads values little-endian from a byte buffer it does not own.
class ByteReader {
 public:
  /// Reads from `position`; past the end it throws `truncated`.
  ByteReader(const std::vector<std::uint8_t>& bytes, std::size_t position, InputError truncated)
      : bytes_(bytes), position_(position), truncated_(std::move(truncated)) {}

  /// \pre T is an arithmetic type of at most 8 bytes.
  /// \throw InputError if fewer than sizeof(T) bytes are left.
  template <class T>
  T get() {
    static_assert(std::is_arithmetic_v<T> && sizeof(T) <= 8, "only numbers have a byte encoding");
    if (position_ + sizeof(T) > bytes_.size()) throw truncated_;
    byte_codec_detail::UnsignedOf<T> bits = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      bits |= static_cast<decltype(bits)>(static_cast<decltype(bits)>(bytes_[position_ + i]) << (8 * i));
    position_ += sizeof(T);
    T value;
    std::memcpy(&value, &bits, sizeof(T));
    return value;
  }

  std::size_t position() const { return position_; }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::size_t position_;
  InputError truncated_;
};

}  // namespace mrsnake
