#include "planner/atoms.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "geometry/morphology.hpp"

namespace hybridctl::planner {
namespace {

std::size_t volume_of(const IndexBox& b) { return std::size_t(b.voxel_count()); }

}  // namespace

AtomDecomposition::AtomDecomposition(const Lattice& lattice, const IndexBox& domain)
    : lattice_(lattice), domain_(domain), codes_{AtomCode(0)}, labels_(volume_of(domain), 0) {
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

void AtomDecomposition::add_primitive(const Solid& primitive) {
  if (!(primitive.lattice() == lattice_)) throw std::invalid_argument("primitive on a different lattice than the atoms");
  const int bit = primitives_++;
  for (AtomCode& c : codes_) c.grow(primitives_);
  const int old_count = atom_count();
  // Each old atom a keeps its number for its part outside the primitive; its part
  // inside gets a new number, made on first sight.
  std::vector<std::int32_t> inside_id(std::size_t(old_count), -1);
  std::vector<std::int64_t> outside_count(std::size_t(old_count), 0);
  const int nx = domain_.hi.x - domain_.lo.x, ny = domain_.hi.y - domain_.lo.y;
  std::size_t i = 0;
  for (int z = domain_.lo.z; z < domain_.hi.z; ++z)
    for (int y = domain_.lo.y; y < domain_.hi.y; ++y)
      for (int xi = 0; xi < nx; ++xi, ++i) {
        const int x = domain_.lo.x + xi;
        const std::int32_t a = labels_[i];
        if (!((primitive.word_at(x >> 6, y, z) >> (x & 63)) & 1u)) {
          ++outside_count[std::size_t(a)];
          continue;
        }
        std::int32_t& id = inside_id[std::size_t(a)];
        if (id < 0) {
          id = std::int32_t(codes_.size());
          AtomCode c = codes_[std::size_t(a)];
          c.set(bit);
          codes_.push_back(c);
        }
        labels_[i] = id;
      }
  (void)ny;
  // Old atoms wholly inside the primitive are now empty: drop them and renumber.
  std::vector<std::int32_t> renumber(codes_.size(), -1);
  std::vector<AtomCode> kept;
  for (std::size_t a = 0; a < codes_.size(); ++a) {
    if (a < std::size_t(old_count) && outside_count[a] == 0) continue;
    renumber[a] = std::int32_t(kept.size());
    kept.push_back(codes_[a]);
  }
  if (kept.size() != codes_.size()) {
    for (std::int32_t& l : labels_) l = renumber[std::size_t(l)];
  }
  codes_ = std::move(kept);
}

AtomDecomposition AtomDecomposition::recompute(const Lattice& lattice, const IndexBox& domain,
                                               const std::vector<const Solid*>& primitives) {
  AtomDecomposition d(lattice, domain);
  const int n = int(primitives.size());
  d.primitives_ = n;
  d.codes_.clear();
  std::unordered_map<AtomCode, std::int32_t, AtomCodeHash> ids;
  std::size_t i = 0;
  AtomCode code(n);
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
  for_each_voxel_label([&](Index3 v, std::int32_t a) {
    if (selected[std::size_t(a)]) out.set(v);
  });
  return out;
}

bool same_partition(const AtomDecomposition& a, const AtomDecomposition& b) {
  if (!(a.domain_ == b.domain_) || a.primitives_ != b.primitives_ || a.codes_.size() != b.codes_.size()) return false;
  for (std::size_t i = 0; i < a.labels_.size(); ++i)
    if (!(a.codes_[std::size_t(a.labels_[i])] == b.codes_[std::size_t(b.labels_[i])])) return false;
  return true;
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

ToleranceZone make_tolerance_zone(const Solid& design, double tolerance_mm) {
  if (tolerance_mm <= 0) return {design, design};
  const geometry::Ball ball{tolerance_mm};
  return {geometry::erode(design, ball), geometry::dilate(design, ball)};
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
  const IndexBox& d = atoms.domain();
  for (int z = d.lo.z; z < d.hi.z; ++z)
    for (int y = d.lo.y; y < d.hi.y; ++y)
      for (int x = d.lo.x; x < d.hi.x; ++x) {
        AtomMeasures& a = out[std::size_t(atoms.atom_at({x, y, z}))];
        ++a.voxels;
        a.voxels_in_design += design.contains({x, y, z});
        a.voxels_in_core += zone.core.contains({x, y, z});
        a.voxels_beyond_hull += !zone.hull.contains({x, y, z});
        IndexBox& b = a.bounding_box;
        b.lo = {std::min(b.lo.x, x), std::min(b.lo.y, y), std::min(b.lo.z, z)};
        b.hi = {std::max(b.hi.x, x + 1), std::max(b.hi.y, y + 1), std::max(b.hi.z, z + 1)};
        Vec3& s = sums[std::size_t(&a - out.data())];
        s = {s.x + x, s.y + y, s.z + z};
      }
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
    const bool in = a.voxels_in_core > 0, out_ = a.voxels_beyond_hull > 0;
    a.atom_class = a.sliver ? AtomClass::Free
                   : in && out_ ? AtomClass::Violating
                   : in         ? AtomClass::MustIn
                   : out_       ? AtomClass::MustOut
                                : AtomClass::Free;
  }
  return out;
}

}  // namespace hybridctl::planner
