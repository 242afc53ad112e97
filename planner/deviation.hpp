#pragma once
// How far a made solid is from the design: the material outside it, the design left
// empty, and how deep each goes, against the tolerance. One measure for the planner's
// plans (plan.json's `deviation`, docs/plan-format.md) and for what a run built
// (`hybridctl dry-run`).

#include "geometry/solid.hpp"

namespace hybridctl::planner {

struct Deviation {
  double over_volume = 0;     // mm^3 of material outside the design
  double under_volume = 0;    // mm^3 of the design left empty
  double worst_over = 0;      // mm: the farthest voxel outside the design from its surface
  double worst_under = 0;     // mm: the farthest empty voxel of the design from its surface
  double worst_distance = 0;  // mm: the larger of the two
  bool within_tolerance = false;
};

// `made` and `design` on one lattice; `domain` bounds the air around the design.
// Distances are between voxel centres less half a voxel: the distance to the surface
// between the voxels.
Deviation measure_deviation(const geometry::Solid& made, const geometry::Solid& design,
                            const geometry::IndexBox& domain, double tolerance);

}  // namespace hybridctl::planner
