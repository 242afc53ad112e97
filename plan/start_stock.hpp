#pragma once
// What a plan starts from when it is executed (validation/, `sim serve --stock`): the raw
// stock of its first action, or nothing, and the box the simulated machine works in; and
// what its cuts must spare (a cut into that is a gouge).

#include "config/machine.hpp"
#include "geometry/solid.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::plan {

// On the plan's lattice, stored over the box the simulated machine works in. A plan that
// starts from a raw stock: that stock, over the plan's domain (deposit beyond the stock's
// box is not lost). A plan that starts with deposition: nothing, over the plan's domain cut
// at the far side of the first deposit's region as seen from its setup's approach (its
// bottom from +Z): the simulated machine stands the lowest layer of its box on the build
// plate (sim/material.hpp), and the deposition toolpath lays the first layer on that plate
// (docs/toolpaths.md, build_plate_z). Throws InputError when that setup is not the machine's.
geometry::Solid start_stock(const PlanFile& file, const PlanFilePlan& plan, const config::Machine& machine);

// The box the simulated machine works in for `plan` (start_stock's storage box): its
// lowest voxel layer in a setup's work frame stands on the build plate there, so plan
// export lays a later deposit's first layer on the same plate. Throws as start_stock.
geometry::IndexBox simulated_domain(const PlanFile& file, const PlanFilePlan& plan, const config::Machine& machine);

// What the cuts of an action must spare: the design the action keeps, shrunk by the
// tolerance. A removal's own region is not spared: SM-cons keeps only the tool's body clear
// of the design, so its region takes design material on purpose, for a later deposit to
// build again (the planner's hybrid plans: mill past the design, then deposit). Whether
// the part as built is right is the deviation's to judge, not the gouge's. Without
// `action`, or for an additive one, the whole design shrunk by the tolerance.
geometry::Solid spared_by_cuts(const PlanFile& file, const PlanFilePrimitive* action = nullptr);

}  // namespace hybridctl::plan
