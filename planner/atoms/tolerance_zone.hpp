#pragma once
// The tolerance zone: which voxels every outcome must hold and which it must leave
// empty, so that an outcome that does is within the tolerance t of the design both ways
// (plan/deviation.hpp: `worst_out` and `worst_missing` at most t).
//
// - The core (design shrunk by t) must be present and everything beyond the hull
//   (design grown by t) must be empty: then no wrong voxel is deeper than t from the
//   design's surface (`worst_out`).
// - That alone lets a plan drop a fin thinner than 2t (it has no core) or fill a slot
//   narrower than 2t (it lies wholly inside the hull): the design's surface there would
//   be far from the part made (`worst_missing`). So every voxel of the design must also
//   lie within t of material every outcome holds, and every voxel of air within t of
//   air every outcome leaves. The core provides that except on `thin`, what an opening
//   by the ball of radius t removes (fins, walls thinner than 2t, the edges and corners
//   of sharp convex edges); the air beyond the hull except on `narrow`, what a closing
//   fills (slots, gaps, sharp concave edges). planner/atoms/thin_parts.hpp chooses, per atom,
//   what covers those.

#include "geometry/solid.hpp"

namespace hybridctl::planner {

struct ToleranceZone {
  geometry::Solid core;    // design (-) ball of radius t: must be present
  geometry::Solid hull;    // design (+) ball of radius t: nothing beyond it may be present
  geometry::Solid thin;    // design voxels farther than t from the core (design minus its opening)
  geometry::Solid narrow;  // air voxels farther than t from beyond the hull (closing minus design)
  double tolerance = 0;    // mm
};

// Distances are between voxel centres, "within t" as the morphology's Ball{t}: at most
// t. A tolerance of 0 (or below) makes the design itself the zone.
ToleranceZone make_tolerance_zone(const geometry::Solid& design, double tolerance_mm);

}  // namespace hybridctl::planner
