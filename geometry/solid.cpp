#include "geometry/solid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hybridctl::geometry {
namespace {

// Floor division by 64 for negative indices too (arithmetic shift is defined in C++20).
int word_of(int x) { return x >> 6; }
int bit_of(int x) { return x & 63; }

void require_same_lattice(const Solid& a, const Solid& b, const char* op) {
  if (!(a.lattice() == b.lattice())) {
    throw std::invalid_argument(std::string(op) + ": solids are on different lattices (voxel " +
                                std::to_string(a.voxel_size()) + " vs " +
                                std::to_string(b.voxel_size()) + " mm or different origins)");
  }
}

enum Op { kUnion, kIntersection, kDifference };

}  // namespace

IndexBox box_union(const IndexBox& a, const IndexBox& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  return {{std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y), std::min(a.lo.z, b.lo.z)},
          {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y), std::max(a.hi.z, b.hi.z)}};
}

IndexBox box_intersection(const IndexBox& a, const IndexBox& b) {
  IndexBox r{{std::max(a.lo.x, b.lo.x), std::max(a.lo.y, b.lo.y), std::max(a.lo.z, b.lo.z)},
             {std::min(a.hi.x, b.hi.x), std::min(a.hi.y, b.hi.y), std::min(a.hi.z, b.hi.z)}};
  return r.empty() ? IndexBox{} : r;
}

IndexBox Lattice::centers_within(const Box3& box) const {
  auto lo = [&](double v, double o) { return int(std::ceil((v - o) / voxel_size - 0.5)); };
  auto hi = [&](double v, double o) { return int(std::floor((v - o) / voxel_size - 0.5)) + 1; };
  IndexBox r{{lo(box.min.x, origin.x), lo(box.min.y, origin.y), lo(box.min.z, origin.z)},
             {hi(box.max.x, origin.x), hi(box.max.y, origin.y), hi(box.max.z, origin.z)}};
  return r.empty() ? IndexBox{} : r;
}

Box3 Lattice::extent(const IndexBox& box) const {
  if (box.empty()) return {origin, origin};
  auto at = [&](Index3 i) {
    return Vec3{origin.x + i.x * voxel_size, origin.y + i.y * voxel_size,
                origin.z + i.z * voxel_size};
  };
  return {at(box.lo), at(box.hi)};
}

Solid::Solid(Lattice lattice, IndexBox domain) : lattice_(lattice) {
  if (!(lattice.voxel_size > 0) || !std::isfinite(lattice.voxel_size)) {
    throw std::invalid_argument("voxel size must be a positive number of mm, got " +
                                std::to_string(lattice.voxel_size));
  }
  if (domain.empty()) return;
  wx0_ = word_of(domain.lo.x);
  wx1_ = word_of(domain.hi.x - 1) + 1;
  y0_ = domain.lo.y;
  y1_ = domain.hi.y;
  z0_ = domain.lo.z;
  z1_ = domain.hi.z;
  words_.assign(std::size_t(wx1_ - wx0_) * std::size_t(y1_ - y0_) * std::size_t(z1_ - z0_), 0);
}

Solid Solid::filled(Lattice lattice, IndexBox domain) {
  Solid s(lattice, domain);
  if (domain.empty()) return s;
  for (int z = domain.lo.z; z < domain.hi.z; ++z)
    for (int y = domain.lo.y; y < domain.hi.y; ++y) s.set_run(y, z, domain.lo.x, domain.hi.x);
  return s;
}

IndexBox Solid::storage_box() const {
  if (words_.empty()) return {};
  return {{wx0_ * kWordBits, y0_, z0_}, {wx1_ * kWordBits, y1_, z1_}};
}

bool Solid::contains(Index3 v) const {
  if (words_.empty() || v.y < y0_ || v.y >= y1_ || v.z < z0_ || v.z >= z1_) return false;
  int w = word_of(v.x);
  if (w < wx0_ || w >= wx1_) return false;
  return (words_[row_offset(v.y, v.z) + std::size_t(w - wx0_)] >> bit_of(v.x)) & 1u;
}

void Solid::set(Index3 v, bool occupied) {
  if (!storage_box().contains(v)) {
    throw std::out_of_range("voxel (" + std::to_string(v.x) + "," + std::to_string(v.y) + "," +
                            std::to_string(v.z) + ") is outside the solid's storage box");
  }
  std::uint64_t& word = words_[row_offset(v.y, v.z) + std::size_t(word_of(v.x) - wx0_)];
  const std::uint64_t mask = std::uint64_t{1} << bit_of(v.x);
  word = occupied ? (word | mask) : (word & ~mask);
}

void Solid::set_run(int y, int z, int x0, int x1) {
  if (x1 <= x0) return;
  const IndexBox storage = storage_box();
  if (!storage.contains({x0, y, z}) || !storage.contains({x1 - 1, y, z})) {
    throw std::out_of_range("run x=[" + std::to_string(x0) + "," + std::to_string(x1) +
                            ") of row y=" + std::to_string(y) + " z=" + std::to_string(z) +
                            " is outside the solid's storage box");
  }
  std::uint64_t* words = words_.data() + row_offset(y, z) - wx0_;  // indexed by absolute word
  const int w0 = word_of(x0), w1 = word_of(x1 - 1);
  const std::uint64_t first = ~std::uint64_t{0} << bit_of(x0);
  const std::uint64_t last = ~std::uint64_t{0} >> (63 - bit_of(x1 - 1));
  if (w0 == w1) {
    words[w0] |= first & last;
    return;
  }
  words[w0] |= first;
  for (int w = w0 + 1; w < w1; ++w) words[w] = ~std::uint64_t{0};
  words[w1] |= last;
}

std::span<const std::uint64_t> Solid::row(int y, int z) const {
  if (y < y0_ || y >= y1_ || z < z0_ || z >= z1_) throw std::out_of_range("row outside storage");
  return {words_.data() + row_offset(y, z), std::size_t(wx1_ - wx0_)};
}

std::span<std::uint64_t> Solid::row(int y, int z) {
  if (y < y0_ || y >= y1_ || z < z0_ || z >= z1_) throw std::out_of_range("row outside storage");
  return {words_.data() + row_offset(y, z), std::size_t(wx1_ - wx0_)};
}

std::int64_t Solid::voxel_count() const {
  std::int64_t n = 0;
  for (std::uint64_t w : words_) n += std::popcount(w);
  return n;
}

double Solid::volume() const {
  const double h = lattice_.voxel_size;
  return double(voxel_count()) * h * h * h;
}

IndexBox Solid::bounding_box() const {
  IndexBox box{{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  bool any = false;
  for (int z = z0_; z < z1_; ++z) {
    for (int y = y0_; y < y1_; ++y) {
      auto r = row(y, z);
      int first = -1, last = -1;
      for (int w = 0; w < int(r.size()); ++w) {
        if (!r[w]) continue;
        if (first < 0) first = w;
        last = w;
      }
      if (first < 0) continue;
      any = true;
      const int xlo = (wx0_ + first) * kWordBits + std::countr_zero(r[first]);
      const int xhi = (wx0_ + last) * kWordBits + (63 - std::countl_zero(r[last])) + 1;
      box.lo = {std::min(box.lo.x, xlo), std::min(box.lo.y, y), std::min(box.lo.z, z)};
      box.hi = {std::max(box.hi.x, xhi), std::max(box.hi.y, y + 1), std::max(box.hi.z, z + 1)};
    }
  }
  return any ? box : IndexBox{};
}

void Solid::for_each_voxel(const std::function<void(Index3)>& fn) const {
  for (int z = z0_; z < z1_; ++z)
    for (int y = y0_; y < y1_; ++y) {
      auto r = row(y, z);
      for (int w = 0; w < int(r.size()); ++w)
        for (std::uint64_t bits = r[w]; bits; bits &= bits - 1)
          fn({(wx0_ + w) * kWordBits + std::countr_zero(bits), y, z});
    }
}

// Applies a word-wise boolean op over `box` (in voxels), reading zeros outside either
// operand's storage.
Solid combine_words(const Solid& a, const Solid& b, IndexBox box, int op) {
  Solid out(a.lattice(), box);
  if (box.empty()) return out;
  auto word_at = [](const Solid& s, int wx, int y, int z) -> std::uint64_t {
    if (s.words_.empty() || y < s.y0_ || y >= s.y1_ || z < s.z0_ || z >= s.z1_ ||
        wx < s.wx0_ || wx >= s.wx1_)
      return 0;
    return s.words_[s.row_offset(y, z) + std::size_t(wx - s.wx0_)];
  };
  for (int z = out.z0_; z < out.z1_; ++z)
    for (int y = out.y0_; y < out.y1_; ++y) {
      std::uint64_t* dst = out.words_.data() + out.row_offset(y, z);
      for (int wx = out.wx0_; wx < out.wx1_; ++wx) {
        const std::uint64_t va = word_at(a, wx, y, z), vb = word_at(b, wx, y, z);
        dst[wx - out.wx0_] = op == kUnion          ? (va | vb)
                             : op == kIntersection ? (va & vb)
                                                   : (va & ~vb);
      }
    }
  return out;
}

Solid unite(const Solid& a, const Solid& b) {
  require_same_lattice(a, b, "union");
  return combine_words(a, b, box_union(a.storage_box(), b.storage_box()), kUnion);
}

Solid copied_onto(const Solid& a, const Lattice& lattice, const IndexBox& box) {
  Solid out(lattice, box);
  a.for_each_voxel([&](Index3 v) {
    if (box.contains(v)) out.set(v);
  });
  return out;
}

Solid intersect(const Solid& a, const Solid& b) {
  require_same_lattice(a, b, "intersection");
  return combine_words(a, b, box_intersection(a.storage_box(), b.storage_box()), kIntersection);
}

Solid subtract(const Solid& a, const Solid& b) {
  require_same_lattice(a, b, "difference");
  return combine_words(a, b, a.storage_box(), kDifference);
}

Solid complement(const Solid& a, const IndexBox& domain) {
  return subtract(Solid::filled(a.lattice(), domain), a);
}

bool operator==(const Solid& a, const Solid& b) {
  if (!(a.lattice() == b.lattice())) return false;
  // Equal iff the symmetric difference is empty.
  return subtract(a, b).voxel_count() == 0 && subtract(b, a).voxel_count() == 0;
}

Solid translate(const Solid& a, Index3 offset) {
  const IndexBox from = a.bounding_box();
  if (from.empty()) return Solid(a.lattice(), {});
  const IndexBox to{{from.lo.x + offset.x, from.lo.y + offset.y, from.lo.z + offset.z},
                    {from.hi.x + offset.x, from.hi.y + offset.y, from.hi.z + offset.z}};
  Solid out(a.lattice(), to);
  const int word_shift = word_of(offset.x), bit_shift = bit_of(offset.x);
  const int out_w0 = out.first_word(), out_w1 = out_w0 + out.words_per_row();
  for (int z = from.lo.z; z < from.hi.z; ++z)
    for (int y = from.lo.y; y < from.hi.y; ++y) {
      auto src = a.row(y, z);
      auto dst = out.row(y + offset.y, z + offset.z);
      for (int w = 0; w < int(src.size()); ++w) {
        const std::uint64_t bits = src[w];
        if (!bits) continue;
        const int target = a.first_word() + w + word_shift;
        if (target >= out_w0 && target < out_w1) dst[target - out_w0] |= bits << bit_shift;
        if (bit_shift && target + 1 >= out_w0 && target + 1 < out_w1)
          dst[target + 1 - out_w0] |= bits >> (64 - bit_shift);
      }
    }
  return out;
}

Solid translate_mm(const Solid& a, Vec3 offset_mm) {
  const double h = a.voxel_size();
  auto voxels = [&](double mm, const char* axis) {
    const double n = mm / h;
    const double rounded = std::round(n);
    if (std::abs(n - rounded) > 1e-6) {
      throw std::invalid_argument(std::string("translation along ") + axis + " of " +
                                  std::to_string(mm) + " mm is not a whole number of " +
                                  std::to_string(h) + " mm voxels");
    }
    return int(rounded);
  };
  return translate(a, {voxels(offset_mm.x, "X"), voxels(offset_mm.y, "Y"), voxels(offset_mm.z, "Z")});
}

Solid rotate_quarter_turns(const Solid& a, Axis axis, int quarter_turns) {
  const int turns = ((quarter_turns % 4) + 4) % 4;
  // One right-handed quarter turn of a voxel about the lattice origin: the centre
  // (i+0.5) maps to -(i+0.5) = (-i-1)+0.5, so negated indices shift by one.
  auto turn = [axis](Index3 v) -> Index3 {
    switch (axis) {
      case Axis::X: return {v.x, -v.z - 1, v.y};
      case Axis::Y: return {v.z, v.y, -v.x - 1};
      case Axis::Z: return {-v.y - 1, v.x, v.z};
    }
    return v;
  };
  auto map = [&](Index3 v) {
    for (int t = 0; t < turns; ++t) v = turn(v);
    return v;
  };
  const IndexBox from = a.bounding_box();
  if (from.empty() || turns == 0) return turns == 0 ? a : Solid(a.lattice(), {});
  // The image of the box is the box spanned by the images of its extreme voxels.
  const Index3 p = map(from.lo), q = map({from.hi.x - 1, from.hi.y - 1, from.hi.z - 1});
  const IndexBox to{{std::min(p.x, q.x), std::min(p.y, q.y), std::min(p.z, q.z)},
                    {std::max(p.x, q.x) + 1, std::max(p.y, q.y) + 1, std::max(p.z, q.z) + 1}};
  Solid out(a.lattice(), to);
  // The map is affine: v -> o + v.x ex + v.y ey + v.z ez, each e a signed unit vector.
  const Index3 o = map({0, 0, 0});
  auto minus_o = [&](Index3 v) { return Index3{v.x - o.x, v.y - o.y, v.z - o.z}; };
  const Index3 ex = minus_o(map({1, 0, 0})), ey = minus_o(map({0, 1, 0})), ez = minus_o(map({0, 0, 1}));
  const IndexBox rows = a.storage_box();
  const int a_first = a.first_word(), out_first = out.first_word();
  const int out_words = out.words_per_row();
  for (int z = rows.lo.z; z < rows.hi.z; ++z)
    for (int y = rows.lo.y; y < rows.hi.y; ++y) {
      const std::span<const std::uint64_t> from_row = a.row(y, z);
      // Where voxel (x, y, z) goes: base + x ex.
      const Index3 base{o.x + y * ey.x + z * ez.x, o.y + y * ey.y + z * ez.y, o.z + y * ey.z + z * ez.z};
      if (ex.x == 1 && ex.y == 0 && ex.z == 0) {
        // About X: the row lands whole on one row, its words where they were.
        bool any = false;
        for (const std::uint64_t w : from_row) any = any || w;
        if (!any) continue;
        const std::span<std::uint64_t> to_row = out.row(base.y, base.z);
        for (int w = std::max(a_first, out_first); w < std::min(a_first + int(from_row.size()), out_first + out_words); ++w)
          to_row[std::size_t(w - out_first)] = from_row[std::size_t(w - a_first)];
        continue;
      }
      for (std::size_t w = 0; w < from_row.size(); ++w)
        for (std::uint64_t bits = from_row[w]; bits; bits &= bits - 1) {
          const int x = (a_first + int(w)) * Solid::kWordBits + std::countr_zero(bits);
          const Index3 t{base.x + x * ex.x, base.y + x * ex.y, base.z + x * ex.z};
          out.row(t.y, t.z)[std::size_t((t.x >> 6) - out_first)] |= std::uint64_t{1} << (t.x & 63);
        }
    }
  return out;
}

}  // namespace hybridctl::geometry
