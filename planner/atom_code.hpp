#pragma once
// An atom's membership code: bit i is set when the atom lies inside primitive i.
// One machine word up to 64 primitives; more words beyond, same interface.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hybridctl::planner {

class AtomCode {
 public:
  AtomCode() = default;
  explicit AtomCode(int primitives) : words_(std::size_t((primitives + 63) / 64), 0) {}

  bool test(int i) const { return (words_[std::size_t(i / 64)] >> (i % 64)) & 1u; }
  void set(int i, bool value = true) {
    const std::uint64_t bit = std::uint64_t{1} << (i % 64);
    auto& w = words_[std::size_t(i / 64)];
    w = value ? (w | bit) : (w & ~bit);
  }
  // Room for one more primitive (codes grow as primitives are added).
  void grow(int primitives) { words_.resize(std::size_t((primitives + 63) / 64), 0); }
  const std::vector<std::uint64_t>& words() const { return words_; }

  // As the paper writes it: the character for P1 first, e.g. "1100".
  std::string bits(int primitives) const {
    std::string s(std::size_t(primitives), '0');
    for (int i = 0; i < primitives; ++i)
      if (test(i)) s[std::size_t(i)] = '1';
    return s;
  }

  friend bool operator==(const AtomCode&, const AtomCode&) = default;

 private:
  std::vector<std::uint64_t> words_;
};

struct AtomCodeHash {
  std::size_t operator()(const AtomCode& c) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint64_t w : c.words()) h = (h ^ w) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return std::size_t(h);
  }
};

}  // namespace hybridctl::planner
