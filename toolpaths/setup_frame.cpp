#include "toolpaths/setup_frame.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hybridctl::toolpaths {
namespace {

using geometry::Axis;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;
using geometry::Vec3;

Vec3 turn_once(const Vec3& p, Axis axis) {
  switch (axis) {
    case Axis::X: return {p.x, -p.z, p.y};
    case Axis::Y: return {p.z, p.y, -p.x};
    case Axis::Z: return {-p.y, p.x, p.z};
  }
  return p;
}

Vec3 turn(Vec3 p, QuarterTurn t) {
  for (int i = 0; i < ((t.quarter_turns % 4) + 4) % 4; ++i) p = turn_once(p, t.axis);
  return p;
}

QuarterTurn inverse(QuarterTurn t) { return {t.axis, (4 - ((t.quarter_turns % 4) + 4) % 4) % 4}; }

// The voxel whose centre is the turned centre of v; throws when that is no voxel centre.
Index3 turn_index(Index3 v, const Lattice& lattice, QuarterTurn t) {
  const Vec3 c = turn(lattice.center(v), t);
  const double h = lattice.voxel_size;
  auto index = [&](double mm, double origin) {
    const double f = (mm - origin) / h - 0.5;
    const double r = std::round(f);
    if (std::abs(f - r) > 1e-6) {
      throw std::invalid_argument("setup frame: the lattice origin (" + std::to_string(lattice.origin.x) + ", " +
                                  std::to_string(lattice.origin.y) + ", " + std::to_string(lattice.origin.z) +
                                  ") mm does not let this quarter turn about the part origin map voxel centres "
                                  "onto voxel centres");
    }
    return int(r);
  };
  return {index(c.x, lattice.origin.x), index(c.y, lattice.origin.y), index(c.z, lattice.origin.z)};
}

IndexBox turn_box(const IndexBox& box, const Lattice& lattice, QuarterTurn t) {
  if (box.empty()) return box;
  const Index3 p = turn_index(box.lo, lattice, t);
  const Index3 q = turn_index({box.hi.x - 1, box.hi.y - 1, box.hi.z - 1}, lattice, t);
  return {{std::min(p.x, q.x), std::min(p.y, q.y), std::min(p.z, q.z)},
          {std::max(p.x, q.x) + 1, std::max(p.y, q.y) + 1, std::max(p.z, q.z) + 1}};
}

Solid turn_solid(const Solid& s, QuarterTurn t) {
  const int turns = ((t.quarter_turns % 4) + 4) % 4;
  if (turns == 0) return s;
  const Lattice& lattice = s.lattice();
  // rotate_quarter_turns turns about the lattice origin o; about the part origin the
  // image is moved by R o - o.
  Solid turned = geometry::rotate_quarter_turns(s, t.axis, turns);
  const Vec3 o = lattice.origin;
  if (o.x == 0 && o.y == 0 && o.z == 0) return turned;
  const Vec3 ro = turn(o, t);
  const Vec3 shift{ro.x - o.x, ro.y - o.y, ro.z - o.z};
  const double h = lattice.voxel_size;
  auto whole = [&](double mm) {
    const double f = mm / h;
    if (std::abs(f - std::round(f)) > 1e-6)
      throw std::invalid_argument("setup frame: the lattice origin does not let this quarter turn map voxels onto voxels");
    return int(std::round(f));
  };
  return geometry::translate(turned, {whole(shift.x), whole(shift.y), whole(shift.z)});
}

}  // namespace

QuarterTurn work_turn(config::Approach approach) {
  switch (approach) {
    case config::Approach::PlusZ: return {Axis::Z, 0};
    case config::Approach::MinusZ: return {Axis::X, 2};
    case config::Approach::PlusX: return {Axis::Y, 3};
    case config::Approach::MinusX: return {Axis::Y, 1};
    case config::Approach::PlusY: return {Axis::X, 1};
    case config::Approach::MinusY: return {Axis::X, 3};
  }
  return {};
}

Vec3 approach_vector(config::Approach approach) {
  switch (approach) {
    case config::Approach::PlusX: return {1, 0, 0};
    case config::Approach::MinusX: return {-1, 0, 0};
    case config::Approach::PlusY: return {0, 1, 0};
    case config::Approach::MinusY: return {0, -1, 0};
    case config::Approach::PlusZ: return {0, 0, 1};
    case config::Approach::MinusZ: return {0, 0, -1};
  }
  return {0, 0, 1};
}

Vec3 part_to_work(const Vec3& p, config::Approach approach) { return turn(p, work_turn(approach)); }
Vec3 work_to_part(const Vec3& p, config::Approach approach) { return turn(p, inverse(work_turn(approach))); }

Index3 part_to_work(Index3 v, const Lattice& lattice, config::Approach approach) {
  return turn_index(v, lattice, work_turn(approach));
}
Index3 work_to_part(Index3 v, const Lattice& lattice, config::Approach approach) {
  return turn_index(v, lattice, inverse(work_turn(approach)));
}

IndexBox part_to_work(const IndexBox& box, const Lattice& lattice, config::Approach approach) {
  return turn_box(box, lattice, work_turn(approach));
}
IndexBox work_to_part(const IndexBox& box, const Lattice& lattice, config::Approach approach) {
  return turn_box(box, lattice, inverse(work_turn(approach)));
}

Solid part_to_work(const Solid& solid, config::Approach approach) { return turn_solid(solid, work_turn(approach)); }
Solid work_to_part(const Solid& solid, config::Approach approach) {
  return turn_solid(solid, inverse(work_turn(approach)));
}

}  // namespace hybridctl::toolpaths
