#pragma once
// Inside corners no instrument makes within the tolerance (docs/search.md, "Inside corners
// no instrument makes"): a refusal before the search, where the voxels cannot see it.
//
// Every face of the part made is last made by a cutter, laid by a head, or left as the raw
// stock had it. At a vertical inside edge of the design that no cutter of the machine comes
// within the tolerance of (every toolpath keeps its cutter, shank and holder out of the
// design: toolpaths/corner_reach.hpp), nothing cuts the faces there, so they stand as laid
// or as the stock has them. A head lays a wall within the tolerance of its programmed face
// only where its accuracy and half its layers' scallop (the bead full width up to its middle
// and narrower above it, under the next layer: instruments::bead_wall_scallop) fit in it:
// past that, some height of every layer stands beyond the tolerance whichever way the
// contour is set. So when no head of the machine fits in the tolerance, such a stretch at
// least two layers tall of every head that fits its accuracy alone, and away from every raw
// stock's faces, is made by nothing: the part is refused, the corners named.

#include <string>
#include <vector>

#include "config/machine.hpp"
#include "plan/candidate_run.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

// How the machine's heads lay walls against the tolerance.
struct WallsAsDeposited {
  bool within = false;     // some head lays a wall within the tolerance as deposited
  double min_stretch = 0;  // mm: a corner's stretch that holds a whole layer of each head
  // Per head, how near it lays walls at best: "ded within 0.31 mm (its accuracy 0.25 mm and
  // half its layers' 0.12 mm scallop)", joined by "; ".
  std::string said;
};

WallsAsDeposited walls_as_deposited(const config::Machine& machine, double tolerance);

// The corners `find` names within the tolerance of `r`'s design that lie farther than it
// from every raw stock's faces (on the voxels, with a voxel to spare); none when some head
// lays walls within the tolerance.
std::vector<plan::UnreachedCorner> corners_no_instrument_makes(const PlanningResult& r, const WallsAsDeposited& walls,
                                                               const plan::CornerFinder& find);

// The refusal over `corners` (not empty).
Verdict corner_refusal(const std::vector<plan::UnreachedCorner>& corners, const WallsAsDeposited& walls,
                       double tolerance);

// "the inside corner at (36.04, 37.96) mm, z 4.3 to 9.5 (93.7 degrees of air): no cutter
// comes within 0.3 mm of it (T3 (8 mm ball finisher) from +Z stays 0.37 mm off)".
std::string corner_in_words(const plan::UnreachedCorner& corner, double tolerance);

}  // namespace hybridctl::planner
