#include "planner/pipeline/shop_words.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "common/number_text.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Index3;

struct Direction {
  Index3 step;
  const char* name;
  config::Approach approach;
};
constexpr std::array<Direction, 6> kDirections{{{{1, 0, 0}, "+X", config::Approach::PlusX},
                                                {{-1, 0, 0}, "-X", config::Approach::MinusX},
                                                {{0, 1, 0}, "+Y", config::Approach::PlusY},
                                                {{0, -1, 0}, "-Y", config::Approach::MinusY},
                                                {{0, 0, 1}, "+Z", config::Approach::PlusZ},
                                                {{0, 0, -1}, "-Z", config::Approach::MinusZ}}};

// The atom's voxels, at most about `cap` of them, evenly.
std::vector<Index3> voxels_of(const geometry::Solid& atom, std::size_t cap) {
  std::vector<Index3> all;
  const geometry::IndexBox b = atom.bounding_box();
  for (int z = b.lo.z; z < b.hi.z; ++z)
    for (int y = b.lo.y; y < b.hi.y; ++y)
      for (int x = b.lo.x; x < b.hi.x; ++x)
        if (atom.contains({x, y, z})) all.push_back({x, y, z});
  if (all.size() <= cap) return all;
  std::vector<Index3> some;
  const double stride = double(all.size()) / double(cap);
  for (std::size_t k = 0; k < cap; ++k) some.push_back(all[std::size_t(double(k) * stride)]);
  return some;
}

// Nothing of the design between `v` and the domain's edge along `d`.
bool open_towards(const geometry::Solid& design, const geometry::IndexBox& domain, Index3 v, Index3 d) {
  for (Index3 p{v.x + d.x, v.y + d.y, v.z + d.z}; domain.contains(p); p = {p.x + d.x, p.y + d.y, p.z + d.z})
    if (design.contains(p)) return false;
  return true;
}

// The width of the gap at `v` across `d` (in the plane square to it), mm: between walls of
// the design on opposite sides along one of the plane's two axes, within `reach` voxels
// each way; the narrower of the two where both have such walls; none (a negative number)
// where neither has: open across, or a corner (walls on one side of each axis only).
double gap_width(const geometry::Solid& design, Index3 v, Index3 d, int reach, double h) {
  const std::array<Index3, 3> axes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  double width = -1;
  for (const Index3& u : axes) {
    if (u.x * d.x + u.y * d.y + u.z * d.z != 0) continue;  // the approach's own axis
    int sides[2] = {0, 0};
    for (int side = 0; side < 2; ++side) {
      const int sign = side == 0 ? 1 : -1;
      for (int k = 1; k <= reach && sides[side] == 0; ++k)
        if (design.contains({v.x + sign * k * u.x, v.y + sign * k * u.y, v.z + sign * k * u.z})) sides[side] = k;
    }
    if (sides[0] == 0 || sides[1] == 0) continue;
    const double w = (sides[0] + sides[1] - 1) * h;
    width = width < 0 ? w : std::min(width, w);
  }
  return width;
}

std::string around(const geometry::Vec3& c) {
  char s[80];
  std::snprintf(s, sizeof s, "(%.1f, %.1f, %.1f) mm", c.x, c.y, c.z);
  return s;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return out;
}

// Closed spaces: `count` regions of `air` mm^3 in all, the first around `at`.
std::string closed_space_words(double air, int count, const geometry::Vec3& at) {
  const std::string volume = trimmed_number(air, air < 10 ? 2 : 0) + " mm\u00B3";
  return std::string("closed space: ") + (count == 1 ? "a " + volume + " cavity" : volume + " of cavities in " + std::to_string(count) + " regions") +
         " around " + around(at) +
         (count == 1 ? " is" : " are") +
         " closed in by the part on every side: no cutter reaches " + (count == 1 ? "it" : "them") +
         " from any direction, and no deposit closes over " + (count == 1 ? "it" : "them") +
         " without something under its first layer; an opening in the design, or the part made in two pieces, would do";
}

// One region of air in words: what it is, why no instrument clears it, what would.
struct AirWords {
  bool closed = false;  // a closed space, said once for all of them
  double air = 0;       // mm^3
  geometry::Vec3 at;    // mm: the middle of its air
  std::string line;     // empty: nothing certain to say
  std::string gap;      // a narrow slot: its width and the side it opens to, which its other regions share
};

AirWords air_in_words(const config::Machine& machine, const PlanningResult& r, const ViolatingAtom& v) {
  const double h = r.lattice.voxel_size;
  // Its air only: an atom that straddles the design holds some of both.
  const std::vector<Index3> voxels = voxels_of(geometry::subtract(r.atoms.atom_solid(v.atom), r.design), 1500);
  if (voxels.empty()) return {};
  AirWords said;
  std::vector<const Direction*> open;
  std::array<std::vector<Index3>, 6> free;
  for (std::size_t k = 0; k < kDirections.size(); ++k) {
    for (const Index3& p : voxels)
      if (open_towards(r.design, r.domain, p, kDirections[k].step)) free[k].push_back(p);
    if (!free[k].empty()) open.push_back(&kDirections[k]);
  }
  geometry::Vec3 at{0, 0, 0};
  for (const Index3& p : voxels) {
    const geometry::Vec3 c = r.lattice.center(p);
    at = {at.x + c.x, at.y + c.y, at.z + c.z};
  }
  const double n = double(voxels.size());
  at = {at.x / n, at.y / n, at.z / n};
  const double air = v.volume - v.volume_in_design;
  const std::string volume = trimmed_number(air, air < 10 ? 2 : 0) + " mm\u00B3";
  said.air = air;
  said.at = at;
  if (open.empty()) {
    said.closed = true;
    return said;
  }
  const auto has_setup = [&](const Direction& d) {
    return std::any_of(machine.setups.begin(), machine.setups.end(),
                       [&](const config::Setup& s) { return s.approach == d.approach; });
  };
  std::vector<std::string> open_names, unset;
  for (const Direction* d : open) {
    open_names.push_back(d->name);
    if (!has_setup(*d)) unset.push_back(d->name);
  }
  if (unset.size() == open.size()) {
    // Air wholly under the part, with -Z among the ways to it: the stock's margin under the
    // part, which only a setup from below reaches (or from the sides, had the machine them).
    double low = 1e300, high = -1e300;
    for (const Index3& p : voxels) {
      const double z = r.lattice.center(p).z;
      low = std::min(low, z), high = std::max(high, z);
    }
    const geometry::Box3 part = r.design.bounding_box_mm();
    const bool under = std::find(unset.begin(), unset.end(), std::string("-Z")) != unset.end() &&
                       high <= part.min.z + r.band + 1e-9;
    const std::string what = under ? "underside: " + trimmed_number(high - low + h, 1) +
                                         " mm of stock under the part around " + around(at)
                                   : "a " + volume + " region around " + around(at);
    said.line = what + " can only be cut from " + joined(unset) + ", and the machine has no setup from " +
                (unset.size() == 1 ? "there" : "any of them") + "; " +
                (under ? "a stock flush with the part's bottom, or a setup from -Z, would do"
                       : "a setup from " + (unset.size() == 1 ? unset.front() : std::string("one of them")) + " would do");
    return said;
  }
  // Open to a setup: do the cutters fit?
  double widest = 0;
  std::string widest_side;
  const config::CuttingTool* smallest = nullptr;
  for (const config::CuttingTool& t : machine.tools)
    if (!smallest || t.diameter < smallest->diameter) smallest = &t;
  if (!smallest) return said;
  // The widest gap the region offers a cutter from a setup's side: the largest over its
  // voxels open to that side; a voxel open across, with no walls on opposite sides, is no
  // slot at all.
  const int reach = int(std::ceil(smallest->diameter / h)) + 1;
  for (std::size_t k = 0; k < kDirections.size(); ++k) {
    if (free[k].empty() || !has_setup(kDirections[k])) continue;
    for (const Index3& p : free[k]) {
      const double w = gap_width(r.design, p, kDirections[k].step, reach, h);
      if (w < 0) return said;
      if (w > widest) widest = w, widest_side = kDirections[k].name;
    }
  }
  if (smallest->diameter > widest + 1e-9) {
    said.gap = trimmed_number(widest, 2) + " " + widest_side;
    said.line = "narrow slot: a " + volume + " gap around " + around(at) + " is " + trimmed_number(widest, 2) +
           " mm wide at most where it opens to " + widest_side + "; the smallest cutter, " + smallest->name + " (" +
           trimmed_number(smallest->diameter, 2) + " mm), does not fit; a cutter of " + trimmed_number(widest, 2) +
           " mm or less across would do";
  }
  // Otherwise open to a setup, and a cutter fits: what stops it is past the part's other
  // walls (shanks, holders) or in combination with other regions; the verdict's list says which.
  return said;
}

}  // namespace

std::vector<std::string> refusal_in_shop_words(const config::Machine& machine, const PlanningResult& r, std::size_t limit) {
  std::vector<std::string> out;
  if (r.verdict.manufacturable() && !r.plans.empty()) return out;
  std::vector<const ViolatingAtom*> air;
  for (const ViolatingAtom& v : r.verdict.violations) {
    const std::size_t a = std::size_t(v.atom);
    if (a < r.problem.atoms.size() && r.problem.atoms[a].must_out) air.push_back(&v);
  }
  // Closed spaces are said once, the regions of air they are split into added up.
  std::size_t closed_line = 0;
  int closed = 0;
  double closed_air = 0;
  geometry::Vec3 closed_at;
  std::vector<std::string> gaps;
  for (const ViolatingAtom* v : air) {
    const AirWords said = air_in_words(machine, r, *v);
    if (said.closed) {
      if (closed++ == 0) closed_line = out.size(), closed_at = said.at, out.emplace_back();
      closed_air += said.air;
      continue;
    }
    if (said.line.empty() || out.size() >= limit) continue;
    // The same slot's other regions (its floor, its ends) say the same thing again.
    if (!said.gap.empty() && std::find(gaps.begin(), gaps.end(), said.gap) != gaps.end()) continue;
    if (!said.gap.empty()) gaps.push_back(said.gap);
    out.push_back(said.line);
  }
  if (closed > 0) out[closed_line] = closed_space_words(closed_air, closed, closed_at);
  return out;
}

}  // namespace hybridctl::planner
