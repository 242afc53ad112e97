#include "planner/pipeline/shop_words.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include "common/number_text.hpp"
#include "instruments/elements.hpp"
#include "instruments/support_rule.hpp"
#include "planner/pipeline/unreached_corners.hpp"
#include "planner/primitives/support.hpp"

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

std::string joined(const std::vector<std::string>& names, const char* last = " and ") {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return out;
}

// Air joined face by face to `seeds` through the voxels `within` accepts: the feature the
// shop sees (a whole cavity, a whole slot), however the atoms split it. `id` (its first
// voxel in the domain's order) tells one from another. None when it reaches the domain's
// edge and `closed` asks for a closed space (the way out bends round the part), or when it
// is larger than kCap voxels.
struct AirBody {
  std::int64_t id = -1;
  std::int64_t voxels = 0;
  geometry::Vec3 at;  // mm: its middle
};

template <class Within>
std::optional<AirBody> air_body(const PlanningResult& r, const std::vector<Index3>& seeds, bool closed, Within within) {
  constexpr std::int64_t kCap = 4'000'000;
  const geometry::IndexBox& d = r.domain;
  const std::int64_t nx = d.hi.x - d.lo.x, ny = d.hi.y - d.lo.y;
  const auto index = [&](Index3 p) { return (std::int64_t(p.z - d.lo.z) * ny + (p.y - d.lo.y)) * nx + (p.x - d.lo.x); };
  std::vector<bool> seen(std::size_t(d.voxel_count()), false);
  std::vector<Index3> queue;
  for (const Index3& p : seeds)
    if (d.contains(p) && !r.design.contains(p) && within(p) && !seen[std::size_t(index(p))])
      seen[std::size_t(index(p))] = true, queue.push_back(p);
  AirBody body;
  double x = 0, y = 0, z = 0;
  for (std::size_t k = 0; k < queue.size(); ++k) {
    if (std::int64_t(queue.size()) > kCap) return std::nullopt;
    const Index3 p = queue[k];
    const std::int64_t i = index(p);
    body.id = body.id < 0 ? i : std::min(body.id, i);
    const geometry::Vec3 m = r.lattice.center(p);
    x += m.x, y += m.y, z += m.z;
    for (const Direction& dir : kDirections) {
      const Index3 q{p.x + dir.step.x, p.y + dir.step.y, p.z + dir.step.z};
      if (!d.contains(q)) {
        if (closed) return std::nullopt;
        continue;
      }
      if (r.design.contains(q) || seen[std::size_t(index(q))] || !within(q)) continue;
      seen[std::size_t(index(q))] = true;
      queue.push_back(q);
    }
  }
  body.voxels = std::int64_t(queue.size());
  if (body.voxels == 0) return std::nullopt;
  const double n = double(body.voxels);
  body.at = {x / n, y / n, z / n};
  return body;
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
  std::int64_t body = -1;  // the cavity or slot it is part of (AirBody::id), said once for all its regions
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
    // The whole cavity, as far as it is closed in: the shop's feature, not the atom's share.
    if (const std::optional<AirBody> c = air_body(r, voxels, true, [](Index3) { return true; })) {
      said.body = c->id;
      said.air = double(c->voxels) * h * h * h;
      said.at = c->at;
    }
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
    // The whole slot: the air joined to this region where the gap is as narrow.
    const auto side = std::find_if(kDirections.begin(), kDirections.end(),
                                   [&](const Direction& d) { return d.name == widest_side; });
    const auto narrow = [&](Index3 p) {
      const double w = gap_width(r.design, p, side->step, reach, h);
      return w >= 0 && w < smallest->diameter - 1e-9;
    };
    std::string slot_volume = volume;
    const std::optional<AirBody> slot =
        side == kDirections.end() ? std::nullopt : air_body(r, voxels, false, narrow);
    if (slot) {
      said.body = slot->id;
      said.air = double(slot->voxels) * h * h * h;
      at = said.at = slot->at;
      slot_volume = trimmed_number(said.air, said.air < 10 ? 2 : 0) + " mm\u00B3";
    }
    said.gap = trimmed_number(widest, 2) + " " + widest_side;
    said.line = "narrow slot: a " + slot_volume + " gap around " + around(at) + " is " + trimmed_number(widest, 2) +
           " mm wide at most where it opens to " + widest_side + "; the smallest cutter, " + smallest->name + " (" +
           trimmed_number(smallest->diameter, 2) + " mm), does not fit; a cutter of " + trimmed_number(widest, 2) +
           " mm or less across would do";
  }
  // Otherwise open to a setup, and a cutter fits: what stops it is past the part's other
  // walls (shanks, holders) or in combination with other regions; the verdict's list says which.
  return said;
}

// ---- Overhangs: design no head builds, over an underside that leans past the head's limit.

// What an overhang needs before it is said (fine-tuning, not the machine's):
constexpr double kLeanMargin = 0.5;    // degrees: a face leans past the limit by at least this
constexpr double kSteepShare = 0.95;   // of the points measured under the region, this many lean past the limit,
constexpr std::size_t kMinPoints = 4;  // and there are at least this many
constexpr double kCutShare = 0.5;      // the rule cuts at least this much of the region's design from every setup
constexpr double kLeanShare = 0.9;     // a head rated for any lean short of flat builds this much of it
constexpr double kRatedMargin = 2.0;   // degrees: a head rated this much past the lean measured is named ...
constexpr double kWholeShare = 0.99;   // ... where it builds this much of the region; a setup the machine lacks,
                                       // where the head builds this much of the whole part from it
constexpr double kFlat = 89.5;         // degrees: a face leaning this much is flat (no head is rated for 90)

// One way of depositing: a head whose primitives deposit, in one setup.
struct BuildWay {
  const config::AdditiveHead* head;
  const config::Setup* setup;
  geometry::AxisDirection direction;
};

std::vector<BuildWay> build_ways(const config::Machine& machine) {
  std::vector<BuildWay> ways;
  for (const config::AdditiveHead& head : machine.heads) {
    const bool deposits = std::any_of(head.primitives.begin(), head.primitives.end(), [](config::PrimitiveKind k) {
      return k == config::PrimitiveKind::UAm || k == config::PrimitiveKind::OAm;
    });
    if (!deposits) continue;
    for (const config::Setup& setup : machine.setups)
      ways.push_back({&head, &setup, instruments::approach_direction(setup.approach)});
  }
  return ways;
}

// The design as a head builds it without support along a way (planner/primitives/support.hpp),
// on the plate or on the one stock every plan starts from, as the deposits are cut.
geometry::Solid design_built(const PlanningResult& r, geometry::AxisDirection build, const config::SupportLimits& limits) {
  const geometry::Solid* present = nullptr;
  const auto stocks = std::count_if(r.primitives.begin(), r.primitives.end(),
                                    [](const Primitive& p) { return p.kind == PrimitiveKind::RawStock; });
  if (r.problem.start_from_stock && stocks == 1 && r.primitives.front().kind == PrimitiveKind::RawStock)
    present = &r.primitives.front().region;
  return self_supporting(r.design, build, instruments::support_rule(limits, r.lattice.voxel_size), present);
}

double share_in(const std::vector<Index3>& voxels, const geometry::Solid& solid) {
  std::size_t in = 0;
  for (const Index3& p : voxels) in += solid.contains(p);
  return voxels.empty() ? 0 : double(in) / double(voxels.size());
}

geometry::Vec3 minus(const geometry::Vec3& a, const geometry::Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
geometry::Vec3 cross(const geometry::Vec3& a, const geometry::Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double dot(const geometry::Vec3& a, const geometry::Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Where the ray from `o` along `d` first meets triangle `t`, within `length` (Moller-Trumbore);
// none (negative) where it does not.
double ray_hit(const geometry::Vec3& o, const geometry::Vec3& d, const geometry::Triangle& t, double length) {
  const geometry::Vec3 e1 = minus(t[1], t[0]), e2 = minus(t[2], t[0]);
  const geometry::Vec3 p = cross(d, e2);
  const double det = dot(e1, p);
  if (std::abs(det) < 1e-12) return -1;
  const geometry::Vec3 s = minus(o, t[0]);
  const double u = dot(s, p) / det;
  if (u < 0 || u > 1) return -1;
  const geometry::Vec3 q = cross(s, e1);
  const double v = dot(d, q) / det, along = dot(e2, q) / det;
  if (v < 0 || u + v > 1 || along <= 0 || along > length) return -1;
  return along;
}

struct UndersidePoint {
  double lean;        // degrees from the build direction
  geometry::Vec3 at;  // mm, on the design's surface
};

// The design's real surface under a region's design voxels, against the build direction:
// from each voxel whose neighbour that way is air (not closed in: a closed space's roof is
// said as the closed space), the STL triangle where the ray from its centre leaves the
// design before that neighbour's centre, and how far the triangle leans from the build
// direction. The ray starts inside the design, so the triangle faces away from the build
// direction whatever the mesh's winding.
std::vector<UndersidePoint> underside_points(const PlanningResult& r, const std::vector<Index3>& voxels,
                                             geometry::AxisDirection build) {
  const double h = r.lattice.voxel_size;
  const Index3 down{build.axis == geometry::Axis::X ? -build.sign : 0, build.axis == geometry::Axis::Y ? -build.sign : 0,
                    build.axis == geometry::Axis::Z ? -build.sign : 0};
  const geometry::Vec3 d{double(down.x), double(down.y), double(down.z)};
  geometry::Box3 near{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (const Index3& p : voxels) {
    const geometry::Vec3 c = r.lattice.center(p);
    near.min = {std::min(near.min.x, c.x - h), std::min(near.min.y, c.y - h), std::min(near.min.z, c.z - h)};
    near.max = {std::max(near.max.x, c.x + h), std::max(near.max.y, c.y + h), std::max(near.max.z, c.z + h)};
  }
  std::vector<const geometry::Triangle*> faces;  // those near the region, not parallel to the build direction
  for (const geometry::Triangle& t : r.design_mesh.triangles) {
    const auto [lo_x, hi_x] = std::minmax({t[0].x, t[1].x, t[2].x});
    const auto [lo_y, hi_y] = std::minmax({t[0].y, t[1].y, t[2].y});
    const auto [lo_z, hi_z] = std::minmax({t[0].z, t[1].z, t[2].z});
    if (hi_x < near.min.x || lo_x > near.max.x || hi_y < near.min.y || lo_y > near.max.y || hi_z < near.min.z ||
        lo_z > near.max.z)
      continue;
    if (std::abs(dot(cross(minus(t[1], t[0]), minus(t[2], t[0])), d)) > 1e-12) faces.push_back(&t);
  }
  std::vector<UndersidePoint> points;
  for (const Index3& p : voxels) {
    const Index3 under{p.x + down.x, p.y + down.y, p.z + down.z};
    if (r.design.contains(under)) continue;
    if (std::none_of(kDirections.begin(), kDirections.end(),
                     [&](const Direction& k) { return open_towards(r.design, r.domain, under, k.step); }))
      continue;
    const geometry::Vec3 o = r.lattice.center(p);
    double nearest = -1;
    const geometry::Triangle* face = nullptr;
    for (const geometry::Triangle* t : faces)
      if (const double along = ray_hit(o, d, *t, 1.001 * h); along > 0 && (nearest < 0 || along < nearest))
        nearest = along, face = t;
    if (!face) continue;  // the voxels and the surface disagree here: nothing measured
    const geometry::Vec3 n = cross(minus((*face)[1], (*face)[0]), minus((*face)[2], (*face)[0]));
    const double sine = std::min(1.0, std::abs(dot(n, d)) / std::sqrt(dot(n, n)));
    points.push_back({std::asin(sine) * 180 / std::numbers::pi, {o.x + nearest * d.x, o.y + nearest * d.y, o.z + nearest * d.z}});
  }
  return points;
}

// An underside leaning past a limit: its lean (the least and the most, the few odd points
// left out) and the middle of its points.
struct Underside {
  double low = 0, high = 0;  // degrees
  geometry::Vec3 at;
  double points = 0;  // how many points `at` is the middle of
};

std::optional<Underside> steep_underside(std::vector<UndersidePoint> points, double limit) {
  if (points.size() < kMinPoints) return std::nullopt;
  std::sort(points.begin(), points.end(), [](const UndersidePoint& a, const UndersidePoint& b) { return a.lean < b.lean; });
  const std::size_t odd = points.size() - std::size_t(std::ceil(kSteepShare * double(points.size())));
  if (points[odd].lean <= limit + kLeanMargin) return std::nullopt;
  Underside u{points[odd].lean, points[points.size() - 1 - odd].lean, {0, 0, 0}};
  for (std::size_t k = odd; k < points.size(); ++k)
    u.at = {u.at.x + points[k].at.x, u.at.y + points[k].at.y, u.at.z + points[k].at.z};
  u.points = double(points.size() - odd);
  u.at = {u.at.x / u.points, u.at.y / u.points, u.at.z / u.points};
  return u;
}

// The ways the machine deposits and what each builds of the design, computed once a
// refusal asks about a region of the design.
struct Builds {
  std::vector<BuildWay> ways;
  std::vector<geometry::Solid> built;  // per way, at its head's limits
  // Along each axis direction (kDirections' order), at the limits of the head with the
  // widest: how much of the design a setup the machine lacks would build (negative: not
  // yet known).
  std::array<double, 6> whole{-1, -1, -1, -1, -1, -1};
};

// An overhang found under a region: the underside, the way (head and setup) it is measured
// from, and whether the machine deposits along other directions too (none builds it).
struct Overhang {
  Underside underside;
  const BuildWay* way = nullptr;
  bool several = false;
  std::vector<std::string> turned;  // the directions a setup the machine lacks would build the part from
  bool rated = false;               // a head rated for the lean measured builds the region
  // The underside's lean and direction: the same underside split among regions is said once.
  std::string key() const {
    return std::to_string(std::lround(underside.low)) + " " + std::to_string(std::lround(underside.high)) + " " +
           std::string(config::to_string(way->setup->approach));
  }
};

// "a", "a, or b", "a, b, or c".
std::string either(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : i + 1 == names.size() ? ", or " : ", ") + names[i];
  return out;
}

// What would build it: a setup the machine lacks from which the head builds the whole
// part, support material (the air under it is open), a head rated for its lean where such
// a head builds the region (none is rated for a flat one; where two faces meet in an
// outside corner, the edge between them leans more than either).
std::string remedies(const Overhang& o) {
  std::vector<std::string> ways;
  if (!o.turned.empty()) ways.push_back("a setup from " + joined(o.turned, " or "));
  ways.push_back("support material");
  if (o.rated) ways.push_back("a head rated for " + std::to_string(std::lround(o.underside.high)) + "\u00B0");
  return either(ways) + (ways.size() == 2 ? "," : "");
}

std::string overhang_words(const Overhang& o) {
  const Underside& u = o.underside;
  const long low = std::lround(u.low), high = std::lround(u.high);
  const std::string lean = u.low >= kFlat   ? "is flat, 90\u00B0 from"
                           : low == high    ? "leans " + std::to_string(low) + "\u00B0 from"
                                            : "leans " + std::to_string(low) + "\u00B0 to " + std::to_string(high) + "\u00B0 from";
  const config::AdditiveHead& head = *o.way->head;
  return "overhang: the underside around " + around(u.at) + " " + lean + " the build direction (" +
         std::string(config::to_string(o.way->setup->approach)) +
         (o.several ? ", setup " + o.way->setup->name + "; no other setup builds it either" : "") + "); the " +
         head.name + " head builds at most " + trimmed_number(head.support.max_overhang, 1) +
         "\u00B0 (support.max_overhang); " + remedies(o) + " would do";
}

// A region of the design that is an overhang: no deposit holds it, the head's limit cuts
// most of its design from every setup, the design's surface under it leans past that limit
// (measured on the STL), and a head rated for a steeper lean would build it. The head with the
// widest limit, from the setup the underside leans least from.
std::optional<Overhang> overhang_of(const PlanningResult& r, const ViolatingAtom& v, Builds& builds) {
  const int atom = v.atom;
  for (const PrimitiveSpec& p : r.problem.primitives)
    if (p.mode == Mode::Additive && !p.raw_stock && std::size_t(atom) < p.atoms.words().size() * 64 && p.atoms.test(atom))
      return std::nullopt;  // a deposit lays it: what stops it is not the head's limit
  if (builds.ways.empty()) return std::nullopt;
  const std::vector<Index3> voxels = voxels_of(geometry::intersect(r.atoms.atom_solid(atom), r.design), 4000);
  if (voxels.empty()) return std::nullopt;
  if (builds.built.empty())
    for (const BuildWay& way : builds.ways) builds.built.push_back(design_built(r, way.direction, way.head->support));
  for (const geometry::Solid& built : builds.built)
    if (share_in(voxels, built) > 1 - kCutShare) return std::nullopt;  // some way builds most of it
  const BuildWay* widest = &builds.ways.front();
  for (const BuildWay& way : builds.ways)
    if (way.head->support.max_overhang > widest->head->support.max_overhang) widest = &way;
  Overhang found;
  std::optional<Underside> best;
  for (const BuildWay& way : builds.ways) {
    if (way.head != widest->head) continue;
    const auto u = steep_underside(underside_points(r, voxels, way.direction), widest->head->support.max_overhang);
    if (u && (!best || u->low < best->low)) best = u, found.way = &way;
  }
  if (!best) return std::nullopt;
  // The lean is what stops the head: one rated for it, or failing that for any lean short
  // of flat (the edges of outside corners lean more than the faces), builds the region.
  config::SupportLimits rated = found.way->head->support;
  rated.max_overhang = std::min(best->high + kRatedMargin, kFlat);
  found.rated = best->high < kFlat && share_in(voxels, design_built(r, found.way->direction, rated)) >= kWholeShare;
  rated.max_overhang = kFlat;
  if (!found.rated && share_in(voxels, design_built(r, found.way->direction, rated)) < kLeanShare) return std::nullopt;
  found.underside = *best;
  for (const BuildWay& way : builds.ways) found.several = found.several || !(way.direction == found.way->direction);
  // The setups the machine lacks from which the head would build the whole part.
  for (std::size_t k = 0; k < kDirections.size(); ++k) {
    const geometry::AxisDirection d = instruments::approach_direction(kDirections[k].approach);
    if (std::any_of(builds.ways.begin(), builds.ways.end(), [&](const BuildWay& way) { return way.direction == d; })) continue;
    if (builds.whole[k] < 0)
      builds.whole[k] = double(design_built(r, d, widest->head->support).voxel_count()) / double(r.design.voxel_count());
    if (builds.whole[k] >= kWholeShare) found.turned.push_back(kDirections[k].name);
  }
  return found;
}

}  // namespace

std::vector<std::string> refusal_in_shop_words(const config::Machine& machine, const PlanningResult& r, std::size_t limit) {
  std::vector<std::string> out;
  if (r.verdict.manufacturable() && !r.plans.empty()) return out;
  if (!r.unreached_corners.empty()) {
    // The corners, as many as leave a line for the rest and one for the heads.
    const std::size_t n = r.unreached_corners.size(), shown = std::min(n, limit > 2 ? limit - 2 : 1);
    for (std::size_t i = 0; i < shown; ++i) out.push_back(corner_in_words(r.unreached_corners[i], r.tolerance));
    if (n > shown)
      out.push_back("and " + std::to_string(n - shown) + " more such corner" + (n - shown == 1 ? "" : "s") +
                    " (plan.json's verdict.unreached_corners)");
    out.push_back("and no head lays a wall within " + trimmed_number(r.tolerance, 3) +
                  " mm as deposited: " + walls_as_deposited(machine, r.tolerance).said);
    return out;
  }
  // Closed spaces are said once, the regions of air they are split into added up.
  std::size_t closed_line = 0;
  int closed = 0;
  double closed_air = 0;
  geometry::Vec3 closed_at;
  std::vector<std::string> gaps;
  std::vector<std::int64_t> bodies;  // the cavities and slots said already
  std::vector<std::pair<std::size_t, Overhang>> overhangs;  // the line each is said on
  Builds builds{build_ways(machine), {}};
  for (const ViolatingAtom& v : r.verdict.violations) {
    const std::size_t a = std::size_t(v.atom);
    if (a >= r.problem.atoms.size()) continue;
    // A region that straddles the design: its air, then its design.
    if (r.problem.atoms[a].must_out) {
      const AirWords said = air_in_words(machine, r, v);
      if (said.closed) {
        // A cavity split among regions is said once, at its whole volume.
        const bool again = said.body >= 0 && std::find(bodies.begin(), bodies.end(), said.body) != bodies.end();
        if (said.body >= 0) bodies.push_back(said.body);
        if (!again) {
          if (closed++ == 0) closed_line = out.size(), closed_at = said.at, out.emplace_back();
          closed_air += said.air;
        }
      } else if (!said.line.empty() && out.size() < limit &&
                 // The same slot's other regions (its floor, its ends) say the same thing again.
                 (said.gap.empty() || std::find(gaps.begin(), gaps.end(), said.gap) == gaps.end()) &&
                 (said.body < 0 || std::find(bodies.begin(), bodies.end(), said.body) == bodies.end())) {
        if (!said.gap.empty()) gaps.push_back(said.gap);
        if (said.body >= 0) bodies.push_back(said.body);
        out.push_back(said.line);
      }
    }
    if (!r.problem.atoms[a].must_in) continue;
    // The same underside split among regions is said once, around the middle of all of it.
    const std::optional<Overhang> o = overhang_of(r, v, builds);
    if (!o) continue;
    const auto same = std::find_if(overhangs.begin(), overhangs.end(),
                                   [&](const auto& said) { return said.second.key() == o->key(); });
    if (same != overhangs.end()) {
      Underside& u = same->second.underside;
      const double n = u.points + o->underside.points;
      u.at = {(u.at.x * u.points + o->underside.at.x * o->underside.points) / n,
              (u.at.y * u.points + o->underside.at.y * o->underside.points) / n,
              (u.at.z * u.points + o->underside.at.z * o->underside.points) / n};
      u.points = n;
      same->second.rated = same->second.rated && o->rated;  // a head so rated builds every region of it
    } else if (out.size() < limit) {
      overhangs.emplace_back(out.size(), *o);
      out.emplace_back();
    }
  }
  if (closed > 0) out[closed_line] = closed_space_words(closed_air, closed, closed_at);
  for (const auto& [line, o] : overhangs) out[line] = overhang_words(o);
  return out;
}

}  // namespace hybridctl::planner
