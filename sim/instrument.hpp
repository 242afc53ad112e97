#pragma once
// The instruments the material simulation sweeps along moves, in the work frame (the
// setup's frame, +Z = the spindle axis pointing away from the part): instruments/ defines
// them once for the planner, the toolpath generators and the simulation.
//
//  - a Cutter (instruments/cutter.hpp): a cutting part and a non-cutting body (shank,
//    holder); the programmed point is the tool TIP.
//  - a Bead (instruments/bead.hpp): an ellipsoid or a cylinder about +Z with an optional
//    nozzle body; the programmed point is the bead's BOTTOM.

#include "instruments/bead.hpp"
#include "instruments/cutter.hpp"

namespace hybridctl::sim {

using instruments::Bead;
using instruments::bead_of;
using instruments::Cutter;
using instruments::cutter_of;

}  // namespace hybridctl::sim
