#pragma once
// Part frame <-> work frame of a setup (gcode/toolpath.hpp documents both frames).
//
// The work frame is the part frame turned by whole quarter turns about a part-frame axis
// through the origin (0, 0, 0) so that the setup's approach direction becomes +Z; the
// origin stays where it is. The turns, part -> work:
//
//   approach   turn                     (x, y, z) in the part frame becomes
//   +Z         none                     ( x,  y,  z)
//   -Z         2 quarter turns about X  ( x, -y, -z)
//   +X         3 quarter turns about Y  (-z,  y,  x)
//   -X         1 quarter turn  about Y  ( z,  y, -x)
//   +Y         1 quarter turn  about X  ( x, -z,  y)
//   -Y         3 quarter turns about X  ( x,  z, -y)
//
// Solids turn exactly (geometry::rotate_quarter_turns) when the turn maps voxel centres
// onto voxel centres, as it does when the lattice origin's coordinates are whole
// multiples of the voxel size (the planner's lattices start at (0, 0, 0)); otherwise the
// functions throw std::invalid_argument.

#include "config/machine.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::toolpaths {

// A right-handed rotation by quarter_turns x 90 degrees about a part-frame axis.
struct QuarterTurn {
  geometry::Axis axis = geometry::Axis::Z;
  int quarter_turns = 0;  // 0..3
};

// The turn that takes the approach direction to +Z (part -> work).
QuarterTurn work_turn(config::Approach approach);
// The approach direction as a unit vector in the part frame (from the part to the tool).
geometry::Vec3 approach_vector(config::Approach approach);

// Points (mm) and free vectors: the turn about the origin.
geometry::Vec3 part_to_work(const geometry::Vec3& p, config::Approach approach);
geometry::Vec3 work_to_part(const geometry::Vec3& p, config::Approach approach);

// Voxel indices on `lattice`: the voxel whose centre is the turned centre.
geometry::Index3 part_to_work(geometry::Index3 v, const geometry::Lattice& lattice, config::Approach approach);
geometry::Index3 work_to_part(geometry::Index3 v, const geometry::Lattice& lattice, config::Approach approach);
// Boxes of voxel indices: the box of the turned voxels.
geometry::IndexBox part_to_work(const geometry::IndexBox& box, const geometry::Lattice& lattice,
                                config::Approach approach);
geometry::IndexBox work_to_part(const geometry::IndexBox& box, const geometry::Lattice& lattice,
                                config::Approach approach);

// Solids, on the same lattice.
geometry::Solid part_to_work(const geometry::Solid& solid, config::Approach approach);
geometry::Solid work_to_part(const geometry::Solid& solid, config::Approach approach);

}  // namespace hybridctl::toolpaths
