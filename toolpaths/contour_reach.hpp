#pragma once
// Contour passes pulled out to the region's edge where the bead would not reach it
// (docs/toolpaths.md, "Raster deposition", step 3).
//
// A layer's contour runs through the centres of the cells of the region shrunk by half a
// bead. On a straight edge along the grid that leaves the outermost voxel centres half a
// voxel from the bead's axis, but on a staircase edge (a blade at 60 degrees, a disc's
// rim) they lie a diagonal, 0.71 voxel, away and in a convex corner (a blade's tip)
// farther; and a bead is narrower than its width near its top, where the upper voxel of a
// band that holds two voxel layers lies (0.66 mm instead of 0.75 for the 1.5 x 0.75 mm
// bead on 0.6 mm layers over 0.5 mm voxels). There the bead misses those voxels, layer
// after layer. reach_edges moves such contour points towards the voxels they must reach,
// as far as needed and never so far that the bead, at its widest, holds the centre of a
// cell outside the region (air the head would lay over, or what must stay empty).
//
//   const int out_of_reach = reach_edges(chains, region, inner, lattice, {cover, clear}, wall);
//   auto chains = voxel_contour(region, wall, lattice, inset, min_length, {cover, clear}, out_of_reach);

#include <vector>

#include "geometry/solid.hpp"
#include "toolpaths/point2.hpp"
#include "toolpaths/slices.hpp"

namespace hybridctl::toolpaths {

struct EdgeReach {
  // How far sideways (mm) a pass lays material at every voxel centre of the layer: the
  // bead's half-width at the highest of them (instruments::bead_half_width_at).
  double cover = 0;
  // How close (mm) a pass may come to the centre of a cell outside the region: the bead's
  // half-width at its widest.
  double clear = 0;
};

// Moves points of `chains` (polylines through cell centres of `inner`'s boundary, in mm;
// a closed chain repeats its first point at its end) so that every cell of `region`
// outside `inner` has its centre within `cover` of a chain, where that keeps every
// sampled point of the chains at least `clear` from the centre of every cell that is in
// neither `region` nor `wall` (material already there, which a bead may fuse with).
// Returns how many of those cells are still farther than `cover` from every chain.
int reach_edges(std::vector<std::vector<Point2>>& chains, const SliceMask& region, const SliceMask& inner,
                const geometry::Lattice& lattice, EdgeReach reach, const SliceMask* wall = nullptr);

// A layer's voxel contour: the boundary cells of the region shrunk by `inset` (mm), as
// polylines through their centres at least `min_length` long, pulled out by reach_edges
// (`wall`: material already there in the layer); `out_of_reach` counts the cells still
// missed.
std::vector<std::vector<Point2>> voxel_contour(const SliceMask& region, const SliceMask& wall,
                                               const geometry::Lattice& lattice, double inset, double min_length,
                                               EdgeReach reach, int& out_of_reach);

}  // namespace hybridctl::toolpaths
