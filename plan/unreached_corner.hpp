#pragma once
// A stretch of a vertical inside edge of the design that no cutter of the machine comes
// near: what toolpaths/corner_reach.hpp finds, and what a refusal names when no head lays
// a wall within the tolerance either (docs/search.md, "Inside corners no instrument
// makes"). In plan.json's terms, so that the planner and the toolpaths share it.

#include <string>

#include "geometry/solid.hpp"

namespace hybridctl::plan {

struct UnreachedCorner {
  geometry::Vec3 from, to;  // mm, part frame: the lowest and highest heights tried and found unreached
  double air_angle = 0;     // degrees: the angle the air makes at the edge
  // mm: the nearest any cutter comes to the edge over the stretch, at least; and which tool
  // from which direction comes that near, as "T4 (4 mm flat detail) from +Z".
  double nearest = 0;
  std::string nearest_by;
};

}  // namespace hybridctl::plan
