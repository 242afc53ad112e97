#pragma once
// Two things a plan keeps apart (docs/plan-format.md, "Tolerance and band"):
//  - the part's tolerance: the drawing's, in mm on the design's real surface, both ways;
//    exact verification (verification/) holds every plan offered to it;
//  - the planning band: how far the voxels of a plan's outcome may lie from the design's
//    voxels before the planner counts them wrong. A voxel is the finest thing the grid
//    resolves, so the band is never under one: no verdict, rejection or "not
//    manufacturable" rests on a region the grid cannot resolve. What lies within the band
//    of the surface is for the toolpaths to get right and for exact verification to judge.

#include <algorithm>

namespace hybridctl::plan {

inline double planning_band(double tolerance_mm, double voxel_mm) { return std::max(tolerance_mm, voxel_mm); }

}  // namespace hybridctl::plan
