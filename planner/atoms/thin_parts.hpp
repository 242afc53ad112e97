#pragma once
// Which atoms features thinner than twice the tolerance, and gaps narrower than it,
// force in or out (the second half of the two-sided classes, planner/atoms/tolerance_zone.hpp).
//
// Atoms are kept or dropped whole, so every voxel of a must-in atom is material in every
// goal outcome, and every voxel of a must-out atom air. A voxel of the zone's `thin`
// part (design the core does not cover) that lies within the tolerance of no must-in
// atom gets one: among the atoms of the design voxels within the tolerance of it, one
// that is neither a sliver nor must-out, preferring one that a primitive made to the
// design holds (a deposit wholly inside it; for air, a removal that never cuts it), then
// the one covering the most, then the deepest voxel (the ridge of the distance field, the
// thin part's medial core), becomes must-in. The voxels are visited
// deepest first, so one choice covers much of a thin part. The same for `narrow` air
// with must-out atoms (air outside the planning domain is always empty). Only when every
// atom near a voxel is must-out (or every one near an air voxel must-in) does the choice
// make an atom violating: then no plan can keep that feature or gap within tolerance.
//
// So an outcome that keeps every must-in atom and no must-out atom is within the
// tolerance both ways, slivers apart: they count as free whatever they hold and are
// chosen only when nothing else is near.

#include <vector>

#include "planner/atoms/atoms.hpp"

namespace hybridctl::planner {

// Sets `thin_feature` and `thin_gap` of the atoms chosen, and their classes.
void mark_thin_parts(const AtomDecomposition& atoms, const Solid& design, const ToleranceZone& zone,
                     std::vector<AtomMeasures>& measures);

}  // namespace hybridctl::planner
