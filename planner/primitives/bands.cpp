#include "planner/primitives/bands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>

#include "instruments/elements.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Axis;
using geometry::AxisDirection;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

int& coordinate(Index3& v, Axis a) { return a == Axis::X ? v.x : a == Axis::Y ? v.y : v.z; }
int coordinate(const Index3& v, Axis a) { return a == Axis::X ? v.x : a == Axis::Y ? v.y : v.z; }

Index3 unit(Axis a, int sign) {
  Index3 d;
  coordinate(d, a) = sign;
  return d;
}

// Voxels per layer across `axis`, indexed from the box's low side.
std::vector<std::int64_t> layer_counts(const Solid& s, Axis axis, const IndexBox& box) {
  std::vector<std::int64_t> n(std::size_t(std::max(0, coordinate(box.hi, axis) - coordinate(box.lo, axis))), 0);
  const int lo = coordinate(box.lo, axis);
  s.for_each_voxel([&](Index3 v) {
    const int c = coordinate(v, axis) - lo;
    if (c >= 0 && std::size_t(c) < n.size()) ++n[std::size_t(c)];
  });
  return n;
}

// The design voxels around `cavity` (within `reach` mm of it) that lie beyond `level`.
Solid wrap_beyond(const Solid& design, const Solid& cavity, double reach, const BandLevel& level) {
  const Solid around = geometry::dilate(cavity, geometry::Ball{reach});
  return intersect(intersect(around, design), beyond(design.lattice(), design.bounding_box(), level));
}

// Cavity floors: the first layer of enclosed air along `build`, by how much floor each
// layer holds (at least a quarter of the largest floor's and of the cavities' shadow);
// kept when some additive primitive holds all the design around the cavity beyond it.
std::vector<BandLevel> cavity_levels(const Solid& design, const Solid& enclosed, double reach, AxisDirection build,
                                     const std::vector<const Solid*>& additive) {
  if (enclosed.empty()) return {};
  // Floor voxels: enclosed, with design before them along `build`: the cavity sits on the
  // design there (the open top of a slot too narrow for any tool is no floor).
  const Solid floor = intersect(enclosed, translate(design, unit(build.axis, build.sign)));
  const IndexBox box = enclosed.bounding_box();
  const std::vector<std::int64_t> per_layer = layer_counts(floor, build.axis, box);
  std::vector<std::pair<std::int64_t, int>> ranked;  // (floor voxels, plane)
  const int lo = coordinate(box.lo, build.axis);
  for (std::size_t c = 0; c < per_layer.size(); ++c)
    if (per_layer[c] > 0) ranked.push_back({per_layer[c], build.sign > 0 ? lo + int(c) : lo + int(c) + 1});
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  // The cavities' shadow across `build`: a floor is a face across the build direction,
  // and covers a good part of it (the side of a round boss under an overhang, seen from the
  // side, is a thin strip of floor on many layers, and no level to mill up to).
  std::set<std::pair<int, int>> shadow;
  const Axis u = build.axis == Axis::X ? Axis::Y : Axis::X, v = build.axis == Axis::Z ? Axis::Y : Axis::Z;
  enclosed.for_each_voxel([&](Index3 p) { shadow.insert({coordinate(p, u), coordinate(p, v)}); });
  std::vector<BandLevel> out;
  for (const auto& [count, plane] : ranked) {
    if (int(out.size()) == kMaxBandLevels || 4 * count < ranked.front().first) break;
    if (4 * count < std::int64_t(shadow.size())) break;
    // A floor's rounded edges (the cavity grown back by a ball) are no floor of their own,
    // nor is a floor a few layers from another.
    if (std::any_of(out.begin(), out.end(), [&](const BandLevel& o) { return std::abs(o.plane - plane) <= 4; })) continue;
    const BandLevel level{build, plane, "cavity floor"};
    const Solid wrap = wrap_beyond(design, enclosed, reach, level);
    const bool buildable = std::any_of(additive.begin(), additive.end(), [&](const Solid* am) {
      return !wrap.empty() && subtract(wrap, *am).empty();
    });
    if (buildable) out.push_back(level);
  }
  return out;
}

// Where the design's section shrinks to half or less from one layer to the next along
// `build` and stays as narrow past it, with a twentieth of the design or more on each
// side, by the area given up.
std::vector<BandLevel> section_levels(const Solid& design, AxisDirection build) {
  const IndexBox box = design.bounding_box();
  const std::vector<std::int64_t> area = layer_counts(design, build.axis, box);
  const int lo = coordinate(box.lo, build.axis);
  std::vector<std::int64_t> prefix(area.size() + 1, 0);  // design in layers [0, c)
  for (std::size_t c = 0; c < area.size(); ++c) prefix[c + 1] = prefix[c] + area[c];
  const std::int64_t total = prefix.back();
  // The largest section past each layer boundary c, in build order.
  std::vector<std::int64_t> widest_past(area.size() + 1, 0);
  if (build.sign > 0)
    for (std::size_t c = area.size(); c-- > 0;) widest_past[c] = std::max(widest_past[c + 1], area[c]);
  else
    for (std::size_t c = 0; c < area.size(); ++c) widest_past[c + 1] = std::max(widest_past[c], area[c]);
  std::vector<std::pair<std::int64_t, int>> ranked;  // (area given up, plane)
  for (std::size_t c = 1; c < area.size(); ++c) {
    // Layers c - 1 and c, in build order.
    const std::size_t before = build.sign > 0 ? c - 1 : c, after = build.sign > 0 ? c : c - 1;
    // Everything past the level stays as narrow: a slot across the section is no step.
    if (2 * widest_past[c] > area[before]) continue;
    // Where a rounded or tapered end of the part thins out, the section halves too, but
    // what lies past it is no feature to deposit on its own: a twentieth of the part at
    // least, and a twentieth before it.
    const std::int64_t past = build.sign > 0 ? total - prefix[c] : prefix[c];
    if (20 * past < total || 20 * (total - past) < total) continue;
    if (area[after] > 0 && 2 * area[after] <= area[before])
      ranked.push_back({area[before] - area[after], lo + int(c)});
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<BandLevel> out;
  for (const auto& r : ranked)
    // A step spread over a few layers (the tangent of a round side) is one step.
    if (std::none_of(out.begin(), out.end(), [&](const BandLevel& o) { return std::abs(o.plane - r.second) <= 4; }))
      out.push_back({build, r.second, "section shrinks"});
  return out;
}

std::string level_words(const BandLevel& level, double h, bool additive) {
  const char* axis = level.build.axis == Axis::X ? "x" : level.build.axis == Axis::Y ? "y" : "z";
  char mm[32];
  std::snprintf(mm, sizeof mm, "%g", level.plane * h);
  const std::string at = std::string(axis) + " = " + mm + " mm";
  if (additive) return (level.build.sign > 0 ? ", from " : ", down from ") + at;
  return (level.build.sign > 0 ? ", down to " : ", up to ") + at;
}

}  // namespace

Solid beyond(const geometry::Lattice& lattice, const IndexBox& domain, const BandLevel& level) {
  IndexBox b = domain;
  if (level.build.sign > 0)
    coordinate(b.lo, level.build.axis) = std::max(coordinate(b.lo, level.build.axis), level.plane);
  else
    coordinate(b.hi, level.build.axis) = std::min(coordinate(b.hi, level.build.axis), level.plane);
  return b.empty() ? Solid(lattice, {}) : Solid::filled(lattice, b);
}

std::vector<BandLevel> band_levels(const Solid& design, const Solid& enclosed, AxisDirection build,
                                   const std::vector<const Solid*>& additive) {
  // The design around a cavity: a voxel away, edges included.
  const double reach = 1.5 * design.voxel_size();
  std::vector<BandLevel> out = cavity_levels(design, enclosed, reach, build, additive);
  for (const BandLevel& l : section_levels(design, build)) {
    if (int(out.size()) == kMaxBandLevels) break;
    if (std::find_if(out.begin(), out.end(), [&](const BandLevel& o) { return o.plane == l.plane; }) == out.end())
      out.push_back(l);
  }
  return out;
}

std::size_t max_banded_primitive_count(const config::Machine& machine) {
  // Per approach direction: each setup's deposits and one cutter; the levels go to at most
  // kMaxBandLevels directions, the largest counted each time.
  bool cutter = false;
  for (const config::CuttingTool& t : machine.tools)
    cutter = cutter || std::find(t.primitives.begin(), t.primitives.end(), config::PrimitiveKind::SmMax) != t.primitives.end();
  std::map<std::pair<int, int>, std::size_t> per_direction;
  for (const config::Setup& setup : machine.setups) {
    std::size_t am = 0;
    for (const config::AdditiveHead& head : machine.heads) am += head.primitives.size();
    if (am == 0) continue;
    const AxisDirection d = instruments::approach_direction(setup.approach);
    per_direction[{int(d.axis), d.sign}] += am + (cutter ? 1 : 0);
  }
  std::size_t largest = 0;
  for (const auto& [direction, n] : per_direction) largest = std::max(largest, n);
  return std::size_t(kMaxBandLevels) * largest;
}

std::vector<Primitive> banded_primitives(const config::Machine& machine, const Solid& design, double tolerance,
                                         const IndexBox& domain, const std::vector<Primitive>& primitives) {
  const Solid hull = tolerance > 0 ? geometry::dilate(design, geometry::Ball{tolerance}) : design;
  // Air every outcome leaves (beyond the hull, inside the design's box) that no removal
  // which spares the design opens (SM-cons cuts into the design to get there): only
  // deposition around it makes it. Grown back by the tolerance, it is the cavity's air up
  // to the design's surface, where its floor is.
  Solid enclosed = subtract(Solid::filled(design.lattice(), design.bounding_box()), hull);
  for (const Primitive& p : primitives)
    if (p.kind == PrimitiveKind::SmMax) enclosed = subtract(enclosed, p.region);
  if (!enclosed.empty() && tolerance > 0)
    enclosed = intersect(subtract(geometry::dilate(enclosed, geometry::Ball{tolerance}), design),
                         Solid::filled(design.lattice(), design.bounding_box()));

  // Per setup, its whole-part deposits and the band's cutter: the cheapest SM-max tool, a
  // flat one first (it faces a flat floor).
  struct Capabilities {
    const config::Setup* setup = nullptr;
    AxisDirection build;
    std::vector<const Primitive*> am;
    const Primitive* facing = nullptr;
  };
  const auto flat = [&](const Primitive* p) {
    const config::CuttingTool* t = machine.find_tool(p->tool_number);
    return t && t->type == config::ToolType::Flat;
  };
  std::vector<Capabilities> setups;
  for (const config::Setup& setup : machine.setups) {
    Capabilities c{&setup, instruments::approach_direction(setup.approach), {}, nullptr};
    for (const Primitive& p : primitives) {
      if (p.setup != setup.name) continue;
      if (p.kind == PrimitiveKind::UAm || p.kind == PrimitiveKind::OAm) c.am.push_back(&p);
      if (p.kind == PrimitiveKind::SmMax &&
          (!c.facing || std::make_pair(!flat(&p), p.cost_per_mm3) < std::make_pair(!flat(c.facing), c.facing->cost_per_mm3)))
        c.facing = &p;
    }
    if (!c.am.empty()) setups.push_back(std::move(c));
  }

  // The candidate levels of every approach, cavity floors first (nothing else makes those
  // cavities), then section steps by what they save: milling the air past the level with
  // the band's cutter against depositing the design past it with the cheapest head.
  struct Candidate {
    BandLevel level;
    bool cavity = false;
    double saving = 0;
  };
  std::vector<Candidate> candidates;
  const Solid box = Solid::filled(design.lattice(), design.bounding_box());
  for (std::size_t i = 0; i < setups.size(); ++i) {
    const Capabilities& c = setups[i];
    const auto same_build = [&](const Capabilities& o) { return o.build == c.build; };
    if (std::find_if(setups.begin(), setups.begin() + std::ptrdiff_t(i), same_build) != setups.begin() + std::ptrdiff_t(i))
      continue;  // setups that share an approach share its levels
    std::vector<const Solid*> regions;
    double deposit_cost = std::numeric_limits<double>::infinity();
    for (const Primitive* p : c.am) regions.push_back(&p->region), deposit_cost = std::min(deposit_cost, p->cost_per_mm3);
    for (const BandLevel& level : band_levels(design, enclosed, c.build, regions)) {
      if (level.why == "cavity floor") {
        candidates.push_back({level, true, 0});
        continue;
      }
      if (!c.facing) continue;
      const Solid past = beyond(design.lattice(), design.bounding_box(), level);
      const double design_past = intersect(design, past).volume();
      const double air_past = intersect(box, past).volume() - design_past;
      const double saving = c.facing->cost_per_mm3 * air_past - deposit_cost * design_past;
      if (saving > 0) candidates.push_back({level, false, saving});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.cavity != b.cavity ? a.cavity : a.saving > b.saving;
  });
  if (candidates.size() > std::size_t(kMaxBandLevels)) candidates.resize(std::size_t(kMaxBandLevels));

  std::vector<Primitive> out;
  const double h = design.voxel_size();
  for (const Candidate& candidate : candidates)
    for (const Capabilities& c : setups) {
      if (!(c.build == candidate.level.build)) continue;
      const Solid past = beyond(design.lattice(), domain, candidate.level);
      for (const Primitive* p : c.am) {
        Primitive b = *p;
        b.label += level_words(candidate.level, h, true);
        b.region = intersect(p->region, past);
        if (b.region.empty()) continue;
        out.push_back(std::move(b));
      }
      if (c.facing) {
        Primitive b = *c.facing;
        b.label += level_words(candidate.level, h, false);
        b.region = unite(c.facing->region, past);
        out.push_back(std::move(b));
      }
    }
  for (std::size_t i = 0; i < out.size(); ++i) out[i].name = primitive_name(primitives.size() + i);
  return out;
}

}  // namespace hybridctl::planner
