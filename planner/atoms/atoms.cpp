#include "planner/atoms/atoms.hpp"

#include "planner/atoms/thin_parts.hpp"

#include <tbb/blocked_range.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <unordered_map>


namespace hybridctl::planner {
namespace {

std::size_t volume_of(const IndexBox& b) { return std::size_t(b.voxel_count()); }

}  // namespace

AtomDecomposition::AtomDecomposition(const Lattice& lattice, const IndexBox& domain)
    : lattice_(lattice), domain_(domain), codes_{AtomSet(0)}, labels_(volume_of(domain), 0) {
  if (domain.empty()) throw std::invalid_argument("atom decomposition over an empty domain");
}

template <typename Fn>
void AtomDecomposition::for_each_voxel_label(Fn fn) const {
  std::size_t i = 0;
  for (int z = domain_.lo.z; z < domain_.hi.z; ++z)
    for (int y = domain_.lo.y; y < domain_.hi.y; ++y)
      for (int x = domain_.lo.x; x < domain_.hi.x; ++x, ++i) fn(Index3{x, y, z}, labels_[i]);
}

int AtomDecomposition::atom_at(Index3 v) const {
  if (!domain_.contains(v)) throw std::out_of_range("voxel outside the planning domain");
  const std::size_t nx = std::size_t(domain_.hi.x - domain_.lo.x), ny = std::size_t(domain_.hi.y - domain_.lo.y);
  return labels_[(std::size_t(v.z - domain_.lo.z) * ny + std::size_t(v.y - domain_.lo.y)) * nx +
                 std::size_t(v.x - domain_.lo.x)];
}

namespace {

// Calls fn(first_label_index, y, z) for every row of the domain, in parallel over z.
template <typename Fn>
void for_each_row(const IndexBox& d, Fn fn) {
  const std::size_t nx = std::size_t(d.hi.x - d.lo.x), ny = std::size_t(d.hi.y - d.lo.y);
  tbb::parallel_for(tbb::blocked_range<int>(d.lo.z, d.hi.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = d.lo.y; y < d.hi.y; ++y)
        fn((std::size_t(z - d.lo.z) * ny + std::size_t(y - d.lo.y)) * nx, y, z);
  });
}

// Calls fn(x) for every x in [x0, x1) set in `solid`'s row (y, z), a word at a time.
template <typename Fn>
void for_each_set_in_row(const Solid& solid, int y, int z, int x0, int x1, Fn fn) {
  for (int w = x0 >> 6; w <= (x1 - 1) >> 6; ++w) {
    std::uint64_t bits = solid.word_at(w, y, z);
    while (bits) {
      const int x = w * 64 + std::countr_zero(bits);
      bits &= bits - 1;
      if (x >= x0 && x < x1) fn(x);
    }
  }
}

}  // namespace

void AtomDecomposition::add_primitive(const Solid& primitive) {
  if (!(primitive.lattice() == lattice_)) throw std::invalid_argument("primitive on a different lattice than the atoms");
  const int bit = primitives_++;
  for (AtomSet& c : codes_) c.grow(primitives_);
  const std::size_t old_count = codes_.size();
  // Pass 1: how much of each old atom lies inside the primitive, and how big it is.
  using Counts = std::vector<std::int64_t>;
  tbb::combinable<std::pair<Counts, Counts>> partial([&] { return std::make_pair(Counts(old_count, 0), Counts(old_count, 0)); });
  const int x0 = domain_.lo.x, x1 = domain_.hi.x;
  for_each_row(domain_, [&](std::size_t first, int y, int z) {
    // Plain references, not a structured binding: clang 14 cannot capture those in a lambda.
    auto& counts = partial.local();
    auto& inside = counts.first;
    auto& size = counts.second;
    const std::int32_t* row = labels_.data() + first;
    for (int i = 0; i < x1 - x0; ++i) ++size[std::size_t(row[i])];
    for_each_set_in_row(primitive, y, z, x0, x1, [&](int x) { ++inside[std::size_t(row[x - x0])]; });
  });
  Counts inside(old_count, 0), size(old_count, 0);
  partial.combine_each([&](const std::pair<Counts, Counts>& p) {
    for (std::size_t a = 0; a < old_count; ++a) {
      inside[a] += p.first[a];
      size[a] += p.second[a];
    }
  });
  // Each old atom keeps its number for its part outside the primitive; its part inside
  // gets a new one, in atom order, so the numbering does not depend on threads. Old atoms
  // wholly inside are then empty and dropped.
  std::vector<std::int32_t> inside_id(old_count, -1);
  for (std::size_t a = 0; a < old_count; ++a) {
    if (inside[a] == 0) continue;
    inside_id[a] = std::int32_t(codes_.size());
    AtomSet c = codes_[a];
    c.set(bit);
    codes_.push_back(c);
  }
  std::vector<std::int32_t> renumber(codes_.size(), -1);
  std::vector<AtomSet> kept;
  for (std::size_t a = 0; a < codes_.size(); ++a) {
    if (a < old_count && inside[a] == size[a]) continue;
    renumber[a] = std::int32_t(kept.size());
    kept.push_back(codes_[a]);
  }
  const bool dropped = kept.size() != codes_.size();
  for (std::size_t a = 0; a < old_count; ++a)
    if (inside_id[a] >= 0) inside_id[a] = renumber[std::size_t(inside_id[a])];
  // Pass 2: relabel. Inside voxels take their atom's inside part; when atoms were
  // dropped, the rest are renumbered (inside voxels are marked negative meanwhile).
  for_each_row(domain_, [&](std::size_t first, int y, int z) {
    std::int32_t* row = labels_.data() + first;
    for_each_set_in_row(primitive, y, z, x0, x1, [&](int x) {
      std::int32_t& l = row[x - x0];
      l = dropped ? -inside_id[std::size_t(l)] - 2 : inside_id[std::size_t(l)];
    });
    if (dropped)
      for (int i = 0; i < x1 - x0; ++i) row[i] = row[i] < 0 ? -row[i] - 2 : renumber[std::size_t(row[i])];
  });
  codes_ = std::move(kept);
}

AtomDecomposition AtomDecomposition::recompute(const Lattice& lattice, const IndexBox& domain,
                                               const std::vector<const Solid*>& primitives) {
  AtomDecomposition d(lattice, domain);
  const int n = int(primitives.size());
  d.primitives_ = n;
  d.codes_.clear();
  std::unordered_map<AtomSet, std::int32_t, AtomSetHash> ids;
  std::size_t i = 0;
  AtomSet code(n);
  for (int z = domain.lo.z; z < domain.hi.z; ++z)
    for (int y = domain.lo.y; y < domain.hi.y; ++y)
      for (int x = domain.lo.x; x < domain.hi.x; ++x, ++i) {
        for (int p = 0; p < n; ++p) code.set(p, (primitives[std::size_t(p)]->word_at(x >> 6, y, z) >> (x & 63)) & 1u);
        auto [it, inserted] = ids.try_emplace(code, std::int32_t(d.codes_.size()));
        if (inserted) d.codes_.push_back(code);
        d.labels_[i] = it->second;
      }
  return d;
}

Solid AtomDecomposition::atom_solid(int atom) const {
  Solid out(lattice_, domain_);
  for_each_voxel_label([&](Index3 v, std::int32_t a) {
    if (a == atom) out.set(v);
  });
  return out;
}

Solid AtomDecomposition::union_of(const std::vector<bool>& selected) const {
  Solid out(lattice_, domain_);
  const int x0 = domain_.lo.x, nx = domain_.hi.x - domain_.lo.x;
  for_each_row(domain_, [&](std::size_t first, int y, int z) {
    const std::int32_t* row = labels_.data() + first;
    auto words = out.row(y, z);
    for (int i = 0; i < nx; ++i)
      if (selected[std::size_t(row[i])]) {
        const int x = x0 + i;
        words[std::size_t((x >> 6) - out.first_word())] |= std::uint64_t{1} << (x & 63);
      }
  });
  return out;
}

bool same_partition(const AtomDecomposition& a, const AtomDecomposition& b) {
  if (!(a.domain_ == b.domain_) || a.primitives_ != b.primitives_ || a.codes_.size() != b.codes_.size()) return false;
  for (std::size_t i = 0; i < a.labels_.size(); ++i)
    if (!(a.codes_[std::size_t(a.labels_[i])] == b.codes_[std::size_t(b.labels_[i])])) return false;
  return true;
}

AtomClass class_of(const AtomMeasures& a) {
  const bool in = a.voxels_in_core > 0 || a.thin_feature, out = a.voxels_beyond_hull > 0 || a.thin_gap;
  return a.sliver ? AtomClass::Free
         : in && out ? AtomClass::Violating
         : in        ? AtomClass::MustIn
         : out       ? AtomClass::MustOut
                     : AtomClass::Free;
}

const char* to_string(AtomClass c) {
  switch (c) {
    case AtomClass::MustIn: return "must-in";
    case AtomClass::MustOut: return "must-out";
    case AtomClass::Free: return "free";
    case AtomClass::Violating: return "violating";
  }
  return "?";
}

std::vector<AtomMeasures> measure_atoms(const AtomDecomposition& atoms, const Solid& design, const ToleranceZone& zone,
                                        double sliver_threshold_mm3) {
  const int m = atoms.atom_count();
  std::vector<AtomMeasures> out(static_cast<std::size_t>(m));
  std::vector<Vec3> sums(static_cast<std::size_t>(m));
  for (int a = 0; a < m; ++a) {
    out[std::size_t(a)].code = atoms.code(a);
    out[std::size_t(a)].bounding_box = {{INT32_MAX, INT32_MAX, INT32_MAX}, {INT32_MIN, INT32_MIN, INT32_MIN}};
  }
  // Per-thread partial sums over rows, combined in atom order.
  struct Partial {
    std::vector<AtomMeasures> m;
    std::vector<Vec3> sums;
  };
  const IndexBox& d = atoms.domain();
  tbb::combinable<Partial> partial([&] { return Partial{out, sums}; });
  const int x0 = d.lo.x, nx = d.hi.x - d.lo.x;
  tbb::parallel_for(tbb::blocked_range<int>(d.lo.z, d.hi.z), [&](const tbb::blocked_range<int>& r) {
    Partial& p = partial.local();
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = d.lo.y; y < d.hi.y; ++y) {
        int x = x0;
        for (int w = x0 >> 6; w <= (d.hi.x - 1) >> 6; ++w) {
          const std::uint64_t in = design.word_at(w, y, z), core = zone.core.word_at(w, y, z),
                              hull = zone.hull.word_at(w, y, z);
          const int end = std::min(d.hi.x, (w + 1) * 64);
          for (; x < end; ++x) {
            const int atom = atoms.atom_at_unchecked(x - x0, y, z);
            AtomMeasures& a = p.m[std::size_t(atom)];
            const int bit = x & 63;
            ++a.voxels;
            a.voxels_in_design += (in >> bit) & 1u;
            a.voxels_in_core += (core >> bit) & 1u;
            a.voxels_beyond_hull += !((hull >> bit) & 1u);
            IndexBox& b = a.bounding_box;
            b.lo = {std::min(b.lo.x, x), std::min(b.lo.y, y), std::min(b.lo.z, z)};
            b.hi = {std::max(b.hi.x, x + 1), std::max(b.hi.y, y + 1), std::max(b.hi.z, z + 1)};
            Vec3& s = p.sums[std::size_t(atom)];
            s = {s.x + x, s.y + y, s.z + z};
          }
        }
        (void)nx;
      }
  });
  partial.combine_each([&](const Partial& p) {
    for (int i = 0; i < m; ++i) {
      AtomMeasures& a = out[std::size_t(i)];
      const AtomMeasures& q = p.m[std::size_t(i)];
      a.voxels += q.voxels;
      a.voxels_in_design += q.voxels_in_design;
      a.voxels_in_core += q.voxels_in_core;
      a.voxels_beyond_hull += q.voxels_beyond_hull;
      IndexBox& b = a.bounding_box;
      const IndexBox& c = q.bounding_box;
      b.lo = {std::min(b.lo.x, c.lo.x), std::min(b.lo.y, c.lo.y), std::min(b.lo.z, c.lo.z)};
      b.hi = {std::max(b.hi.x, c.hi.x), std::max(b.hi.y, c.hi.y), std::max(b.hi.z, c.hi.z)};
      Vec3& s = sums[std::size_t(i)];
      const Vec3& t = p.sums[std::size_t(i)];
      s = {s.x + t.x, s.y + t.y, s.z + t.z};
    }
  });
  const double h = atoms.lattice().voxel_size, v = h * h * h;
  for (int i = 0; i < m; ++i) {
    AtomMeasures& a = out[std::size_t(i)];
    a.volume = double(a.voxels) * v;
    a.volume_in_design = double(a.voxels_in_design) * v;
    if (a.voxels > 0) {
      const Vec3& s = sums[std::size_t(i)];
      a.centroid = atoms.lattice().center({0, 0, 0});
      a.centroid = {a.centroid.x + s.x / double(a.voxels) * h, a.centroid.y + s.y / double(a.voxels) * h,
                    a.centroid.z + s.z / double(a.voxels) * h};
    }
    a.sliver = a.volume < sliver_threshold_mm3;
    a.atom_class = class_of(a);
  }
  mark_thin_parts(atoms, design, zone, out);
  return out;
}

}  // namespace hybridctl::planner
