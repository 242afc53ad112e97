#pragma once
// Reads a fuzz input front to back as the arguments of a sequence of operations, so a
// seed file can be written by hand (fuzz/corpus/make-seeds): integers are big-endian,
// a byte string is its length byte then its bytes. Past the end everything reads as 0 /
// empty, so every input is a valid program.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace hybridctl::fuzz {

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> data) : data_(data) {}

  bool empty() const { return pos_ >= data_.size(); }

  std::uint8_t u8() { return pos_ < data_.size() ? data_[pos_++] : 0; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(u8() << 8 | u8()); }
  std::uint32_t u32() { return std::uint32_t{u16()} << 16 | u16(); }
  std::uint64_t u64() { return std::uint64_t{u32()} << 32 | u32(); }
  bool flag() { return (u8() & 1u) != 0; }

  /// `count` bytes (fewer at the end of the input).
  std::vector<std::uint8_t> bytes(std::size_t count) {
    const std::size_t n = std::min(count, data_.size() - std::min(pos_, data_.size()));
    std::vector<std::uint8_t> out(data_.begin() + static_cast<std::ptrdiff_t>(pos_),
                                  data_.begin() + static_cast<std::ptrdiff_t>(pos_ + n));
    pos_ += n;
    return out;
  }
  /// A length byte (or u16 when `wide`), then that many bytes.
  std::vector<std::uint8_t> sized_bytes(bool wide = false) { return bytes(wide ? u16() : u8()); }
  std::string sized_string(bool wide = false) {
    const auto b = sized_bytes(wide);
    return std::string(b.begin(), b.end());
  }

 private:
  std::span<const std::uint8_t> data_;
  std::size_t pos_ = 0;
};

}  // namespace hybridctl::fuzz
