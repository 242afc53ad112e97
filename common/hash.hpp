#pragma once
// The project's one non-cryptographic hash, FNV-1a 64 (offset basis 0xCBF29CE484222325,
// prime 0x100000001B3): the program identity the host and controller agree on
// (docs/protocol.md), a machine file's hash in plan.json, a solid's in the report; and
// the same basis and prime a 64-bit word at a time for hash tables keyed by bit sets.
// "a" -> 0xAF63DC4C8601EC8C.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace hybridctl {

class Fnv1a64 {
 public:
  static constexpr std::uint64_t kOffsetBasis = 0xCBF29CE484222325ull;
  static constexpr std::uint64_t kPrime = 0x100000001B3ull;

  void update(std::span<const std::uint8_t> bytes) {
    for (std::uint8_t b : bytes) state_ = (state_ ^ b) * kPrime;
  }
  void update(std::string_view text) {
    for (char c : text) state_ = (state_ ^ static_cast<std::uint8_t>(c)) * kPrime;
  }
  // The word's eight bytes, least significant first (its bytes in memory on x86-64).
  void update_word(std::uint64_t word) {
    for (int b = 0; b < 8; ++b) state_ = (state_ ^ ((word >> (8 * b)) & 0xff)) * kPrime;
  }
  std::uint64_t value() const { return state_; }

 private:
  std::uint64_t state_ = kOffsetBasis;
};

inline std::uint64_t fnv1a64(std::string_view text) {
  Fnv1a64 h;
  h.update(text);
  return h.value();
}

// For hash tables keyed by words (search states, duplicate keys): FNV's basis and prime a
// whole word at a time, which is fast, with a shift that folds the high bits the multiply
// leaves alone into the low bits a table's buckets use.
struct WordsHash {
  std::size_t operator()(const std::vector<std::uint64_t>& words) const {
    std::uint64_t h = Fnv1a64::kOffsetBasis;
    for (std::uint64_t w : words) h = (h ^ w) * Fnv1a64::kPrime, h ^= h >> 29;
    return std::size_t(h);
  }
};

}  // namespace hybridctl
