#pragma once
// A set of small indices, one bit each: the atoms a state, a primitive or a plan's region
// holds (bit a: atom a), and an atom's membership code (bit i: the atom lies inside
// primitive i). One machine word up to 64 members; more words beyond, same interface.

#include <cstdint>
#include <string>
#include <vector>

namespace hybridctl::planner {

class AtomSet {
 public:
  AtomSet() = default;
  // Room for members 0 .. size-1, none present.
  explicit AtomSet(int size) : words_(std::size_t((size + 63) / 64), 0) {}

  bool test(int i) const { return (words_[std::size_t(i / 64)] >> (i % 64)) & 1u; }
  void set(int i, bool value = true) {
    const std::uint64_t bit = std::uint64_t{1} << (i % 64);
    auto& w = words_[std::size_t(i / 64)];
    w = value ? (w | bit) : (w & ~bit);
  }
  // Room for members up to size-1 (codes grow as primitives are added).
  void grow(int size) { words_.resize(std::size_t((size + 63) / 64), 0); }
  const std::vector<std::uint64_t>& words() const { return words_; }
  std::vector<std::uint64_t>& words() { return words_; }

  // As the paper writes a code: the character for P1 first, e.g. "1100".
  std::string bits(int size) const {
    std::string s(std::size_t(size), '0');
    for (int i = 0; i < size; ++i)
      if (test(i)) s[std::size_t(i)] = '1';
    return s;
  }

  friend bool operator==(const AtomSet&, const AtomSet&) = default;

 private:
  std::vector<std::uint64_t> words_;
};

// A relation between atoms, one set per atom (what blocks a head from it, what may carry
// it), with each set's non-zero words kept apart as well: the search asks per atom it
// deposits whether its set meets the state, millions of times, and the sets are sparse
// (a few atoms in thousands), so it reads only those words.
class AtomRelation {
 public:
  AtomRelation() = default;
  explicit AtomRelation(std::vector<AtomSet> sets) : sets_(std::move(sets)) {
    begin_.reserve(sets_.size() + 1);
    for (const AtomSet& s : sets_) {
      begin_.push_back(std::uint32_t(index_.size()));
      const auto& w = s.words();
      for (std::size_t k = 0; k < w.size(); ++k)
        if (w[k]) index_.push_back(std::uint32_t(k)), words_.push_back(w[k]);
    }
    begin_.push_back(std::uint32_t(index_.size()));
  }
  std::size_t size() const { return sets_.size(); }
  // The set of atom a (no words: empty).
  const AtomSet& operator[](std::size_t a) const { return sets_[a]; }
  // Whether the set of atom a holds a member of `state` (words of an AtomSet).
  bool meets(std::size_t a, const std::vector<std::uint64_t>& state) const {
    for (std::uint32_t e = begin_[a]; e < begin_[a + 1]; ++e)
      if (words_[e] & state[index_[e]]) return true;
    return false;
  }

 private:
  std::vector<AtomSet> sets_;
  std::vector<std::uint32_t> begin_;  // per atom, where its non-zero words start
  std::vector<std::uint32_t> index_;  // their word indices
  std::vector<std::uint64_t> words_;  // and the words
};

struct AtomSetHash {
  std::size_t operator()(const AtomSet& c) const {
    std::uint64_t h = 0x9E3779B97F4A7C15ull;
    for (std::uint64_t w : c.words()) h = (h ^ w) * 0xBF58476D1CE4E5B9ull, h ^= h >> 31;
    return std::size_t(h);
  }
};

}  // namespace hybridctl::planner
