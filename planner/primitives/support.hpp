#pragma once
// Physics in the additive primitives: the part of a deposit a head can build layer by
// layer without support, in its setup's build direction (docs/support.md).
//
// The deposit starts on a build plate under its first layer (the lowest along the build
// direction) and grows one voxel layer at a time; each layer keeps the voxels the head's
// rule (instruments/support_rule.hpp, the same rule the simulator applies) holds on the
// layer kept below it. What an overhang steeper than the head's cone or a bridge longer
// than it may span would need is cut, and so is everything built on top of it.
//
// The nozzle needs no test here: it stands `standoff` (more than a bead height, the
// machine loader checks) above the layer being laid, and every voxel deposited before in
// the same build lies in that layer or below, so it never touches them. Material that is
// there before the build (stock, earlier actions) is the plan's state: the simulator
// checks the nozzle against it when a plan is executed.

#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"
#include "instruments/support_rule.hpp"

namespace hybridctl::planner {

// The self-supporting part of `region` built along `build` (the setup's approach: the
// head comes from that side, layers stack towards it).
// `present`, when given, is material there before the build (a stock to build on): its
// voxels hold in every layer, and carry what is built over and beside them.
geometry::Solid self_supporting(const geometry::Solid& region, geometry::AxisDirection build,
                                const instruments::SupportRule& rule, const geometry::Solid* present = nullptr);

}  // namespace hybridctl::planner
