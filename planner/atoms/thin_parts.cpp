#include "planner/atoms/thin_parts.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "geometry/distance_field.hpp"
#include "geometry/morphology.hpp"

namespace hybridctl::planner {
namespace {

enum class Side { Material, Air };

// An atom every goal outcome holds (material), or leaves empty (air).
bool holds(const AtomMeasures& m) { return !m.sliver && (m.atom_class == AtomClass::MustIn || m.atom_class == AtomClass::Violating); }
bool clears(const AtomMeasures& m) { return !m.sliver && (m.atom_class == AtomClass::MustOut || m.atom_class == AtomClass::Violating); }

// The voxels of `region`, those farthest from the other side first (ties in z, y, x
// order), and the distance field that ordered them: it spans `region` grown by `reach`
// voxels, where every candidate for covering a voxel lies.
struct DeepestFirst {
  std::vector<Index3> voxels;
  geometry::DistanceField depth;
};
DeepestFirst deepest_first(const Solid& region, const Solid& design, Side side, int reach) {
  const IndexBox b = region.bounding_box();
  const IndexBox box{{b.lo.x - reach, b.lo.y - reach, b.lo.z - reach}, {b.hi.x + reach, b.hi.y + reach, b.hi.z + reach}};
  const Solid other = side == Side::Material ? complement(design, box) : intersect(design, Solid::filled(design.lattice(), box));
  DeepestFirst d{{}, geometry::DistanceField(other, box)};
  std::vector<std::pair<float, Index3>> order;
  region.for_each_voxel([&](Index3 v) { order.push_back({d.depth.squared(v), v}); });
  std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [depth, v] : order) d.voxels.push_back(v);
  return d;
}

// Whether two sets share a member.
bool shares(const AtomSet& a, const AtomSet& b) {
  const std::size_t n = std::min(a.words().size(), b.words().size());
  for (std::size_t w = 0; w < n; ++w)
    if (a.words()[w] & b.words()[w]) return true;
  return false;
}

// The primitives made to the design: those wholly inside it (deposits that lay only the
// design) and those wholly outside it (removals that never cut it). Where several atoms
// could keep a thin part or a gap, one of theirs is the choice a plan can honour without
// a tool's or a bead's voxels fitting the surface exactly: on a round bore's edge the
// voxels a cutter's sweep leaves are scattered, the ones beside them are clear.
struct CleanPrimitives {
  AtomSet inside, outside;
};
CleanPrimitives clean_primitives(int primitive_count, const std::vector<AtomMeasures>& m) {
  AtomSet touches_design(primitive_count), touches_air(primitive_count);
  auto add = [](AtomSet& into, const AtomSet& code) {
    for (std::size_t w = 0; w < std::min(code.words().size(), into.words().size()); ++w) into.words()[w] |= code.words()[w];
  };
  for (const AtomMeasures& a : m) {
    if (a.voxels_in_design > 0) add(touches_design, a.code);
    if (a.voxels_in_design < a.voxels) add(touches_air, a.code);
  }
  CleanPrimitives c{AtomSet(primitive_count), AtomSet(primitive_count)};
  for (int i = 0; i < primitive_count; ++i) {
    c.inside.set(i, touches_design.test(i) && !touches_air.test(i));
    c.outside.set(i, touches_air.test(i) && !touches_design.test(i));
  }
  return c;
}

// Makes every voxel of `region` lie within the ball of an atom that holds it (material)
// or clears it (air), choosing atoms as planner/atoms/thin_parts.hpp says. `pending` tracks
// the voxels of `region` no chosen voxel covers yet, to prefer a candidate that covers
// many; atoms that were must-in (must-out) before cover too, which the scan finds.
void cover(const AtomDecomposition& atoms, const Solid& design, const Solid& region, Side side, double tolerance,
           const AtomSet& clean, std::vector<AtomMeasures>& m) {
  if (region.empty()) return;
  const double h = design.voxel_size();
  const std::vector<Index3> offsets = geometry::offsets_of(geometry::Ball{tolerance}, h);
  const DeepestFirst order = deepest_first(region, design, side, int(std::floor(tolerance / h)) + 1);
  const IndexBox& domain = atoms.domain();
  const bool material = side == Side::Material;
  // A candidate's gain is counted on a sample of its ball: with a tolerance of many
  // voxels, counting all of it for every candidate would cost the ball's size squared.
  constexpr std::size_t kGainSamples = 125;
  std::vector<Index3> sample;
  for (std::size_t i = 0; i < offsets.size(); i += std::max<std::size_t>(1, offsets.size() / kGainSamples))
    sample.push_back(offsets[i]);
  Solid pending = region;
  auto around = [](Index3 c, const std::vector<Index3>& ball, auto fn) {
    for (const Index3& d : ball) fn(Index3{c.x + d.x, c.y + d.y, c.z + d.z});
  };
  for (const Index3& u : order.voxels) {
    if (!pending.contains(u) || !domain.contains(u)) continue;  // outside the domain nothing is ever made
    bool covered = false;
    for (const Index3& d : offsets) {
      const Index3 v{u.x + d.x, u.y + d.y, u.z + d.z};
      const bool beyond = !domain.contains(v);
      if ((beyond && !material) || (!beyond && (material ? holds : clears)(m[std::size_t(atoms.atom_at(v))]))) {
        covered = true;  // air beyond the domain stays air
        break;
      }
    }
    if (covered) continue;
    // Candidates lie on u's side. Rather a free atom than a sliver (not relied on),
    // rather a sliver than making an atom violating; then one that a primitive made to
    // the design can get right (`clean`); then the one covering the most pending voxels,
    // then the deepest (the medial core).
    std::tuple<int, bool, int, float> best{-1, false, 0, 0};
    Index3 chosen{};
    around(u, offsets, [&](Index3 v) {
      if (!domain.contains(v) || design.contains(v) != material) return;
      const AtomMeasures& a = m[std::size_t(atoms.atom_at(v))];
      const int tier = a.sliver ? 1 : (material ? clears(a) : holds(a)) ? 0 : 2;
      int gain = 0;
      around(v, sample, [&](Index3 w) { gain += pending.contains(w); });
      const std::tuple<int, bool, int, float> score{tier, shares(a.code, clean), gain, order.depth.squared(v)};
      if (score > best) {
        best = score;
        chosen = v;
      }
    });
    if (std::get<0>(best) < 0) continue;
    AtomMeasures& a = m[std::size_t(atoms.atom_at(chosen))];
    (material ? a.thin_feature : a.thin_gap) = true;
    a.atom_class = class_of(a);
    if (!a.sliver)
      around(chosen, offsets, [&](Index3 w) {
        if (pending.contains(w)) pending.set(w, false);
      });
  }
}

}  // namespace

void mark_thin_parts(const AtomDecomposition& atoms, const Solid& design, const ToleranceZone& zone,
                     std::vector<AtomMeasures>& measures) {
  if (zone.tolerance <= 0) return;
  const CleanPrimitives clean = clean_primitives(atoms.primitive_count(), measures);
  cover(atoms, design, zone.thin, Side::Material, zone.tolerance, clean.inside, measures);
  cover(atoms, design, zone.narrow, Side::Air, zone.tolerance, clean.outside, measures);
}

}  // namespace hybridctl::planner
