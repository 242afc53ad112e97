#pragma once
// Filled deposits: a supported envelope, deposited and milled back (docs/support.md).
//
// A head's O-AM holds only what it builds layer by layer without support (support.hpp):
// under the roof of a horizontal hole or a channel, or under an overhang, the cut takes
// the unsupported layer and everything built on it. A shop deposits the envelope solid
// instead, the hole filled, and mills the hole out from the side. The filled O-AM is the
// head's O-AM before the support cut with every column along the build direction filled
// down to its first layer: each column stands on the one under it, so it needs no
// support, and its top is the envelope's, which the nozzle reaches from the approach side.
//
// Offered only where it pays, per O-AM of the machine: the support cut took design
// material from it, and at least kFilledRemovable of what the filling adds outside the
// design is in some removal primitive (a hole a side setup's cutter opens), so that
// milling can give the design back. At most one per head and setup.

#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"
#include "planner/primitives/machine_primitives.hpp"

namespace hybridctl::planner {

inline constexpr double kFilledRemovable = 0.95;

// `region` with each column along `build` filled from the region's first layer (its
// lowest along `build`) up to the column's highest voxel, within `domain`.
geometry::Solid column_filled(const geometry::Solid& region, geometry::AxisDirection build, const geometry::IndexBox& domain);

// The most filled primitives filled_primitives may add for `machine`: one per head and
// setup that has an O-AM (for the memory check before anything is computed).
std::size_t max_filled_primitive_count(const config::Machine& machine);

// The filled O-AMs for `primitives` (the machine's whole-part ones, as machine_primitives
// returns them, with the removal primitives among them), labelled "..., filled". Not yet
// named: the caller numbers them after the others.
std::vector<Primitive> filled_primitives(const config::Machine& machine, const geometry::Solid& design,
                                         const geometry::IndexBox& domain, const std::vector<Primitive>& primitives);

}  // namespace hybridctl::planner
