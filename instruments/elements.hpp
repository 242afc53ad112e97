#pragma once
// Instruments as morphology's structuring elements (geometry/morphology.hpp), for the
// two users that dilate with them:
//
//  - the planner's primitives, in the part frame of a setup: a profile laid along the
//    setup's approach direction, from the tip towards the approach side (axial_body), and
//    a bead as the element the planner deposits with (bead_element);
//  - the pocket generator's guard, in the work frame (axis +Z), on a lattice of voxel size
//    h: a profile made conservative along its axis (conservative_guard).
//
// The guard. Morphology samples an element at whole voxel offsets (offset d belongs to
// it when d * h lies in the shape), so a tool checked against the voxels with its tip on
// a voxel-centre height says nothing about tips between two heights. The guard's level t
// (the offsets t voxels above the tip) has the largest radius the exact profile reaches
// anywhere in [(t - 1) h, t h]; an infinite last section stays infinite. So:
//  - conservative: with its tip on a voxel-centre height z, the guard's offsets hold the
//    exact shape's offsets for every tip height in [z, z + h] (ramps, plunges and
//    retracts between levels are as safe as tips on them);
//  - tight: it is the exact shape swept one voxel down its own axis and no more; sideways
//    it is no larger (level t's radius is the exact profile's at some height within one
//    voxel below t h).

#include <vector>

#include "config/machine.hpp"
#include "geometry/morphology.hpp"
#include "instruments/bead.hpp"

namespace hybridctl::instruments {

// Samples per voxel when a profile's radius is scanned along its axis (the guard, and the
// pocket generator's reach of the tool); every section's ends and centre are sampled too.
inline constexpr int kProfileSamplesPerVoxel = 32;

// The direction of a setup's approach (from the part towards the tool), along a lattice axis.
geometry::AxisDirection approach_direction(config::Approach approach);

// A profile (sections from the tip) as an axial body along the approach direction.
geometry::AxialBody axial_body(std::vector<geometry::AxialSection> profile, config::Approach approach);

// The planner's element of a bead deposited from `approach`: an ellipsoid centred at the
// origin (semi-axes width/2 across, height/2 along the approach) or a cylinder of radius
// width/2 over [0, height] along it. The nozzle body is not part of it: it constrains the
// toolpath's clearance moves, not the depositable shape.
geometry::StructuringElement bead_element(const Bead& bead, config::Approach approach);

// The conservative guard of a profile (tip at the origin, axis +Z) on a lattice of voxel
// size `voxel_size`: level t is a cylinder over [t h - h/4, t h + h/4] as described above.
geometry::AxialBody conservative_guard(const std::vector<geometry::AxialSection>& profile, double voxel_size);

}  // namespace hybridctl::instruments
