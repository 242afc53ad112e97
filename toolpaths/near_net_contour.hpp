#pragma once
// A near-net layer's contour (docs/toolpaths.md, "Deposition", step 3): the bead axes on
// the design's exact cross-section shrunk by half a bead, where they run over the layer's
// region, instead of the voxel chains there. A voxel chain is a staircase of voxel
// centres: on a thin wall across the grid it zigzags within the wall and leaves one
// face's bead out, and it cuts a convex corner that the exact loop turns.
//
//   NearNetContour c = near_net_contour(axes, region, voxel_chains, lattice, bead);
//   ... rasters ...
//   auto middle = near_net_gap_loops(axes, region, lattice, bead, hatch_spacing);
//
// The voxel chains stay where no exact axis runs near them (within half a bead): the
// region's edges that are not the design's walls, e.g. against material already there.
// A thin wall's middle, which rasters only cross, takes a second loop (near_net_gap_loops).

#include <vector>

#include "geometry/solid.hpp"
#include "toolpaths/point2.hpp"
#include "toolpaths/slices.hpp"
#include "toolpaths/wall_finish.hpp"

namespace hybridctl::toolpaths {

// The bead as the contour lays it (mm).
struct NearNetBead {
  double half_width = 0;
  // How far inside the design's faces the axes run (section_shrunk's inset).
  double axis_inset = 0;
  // The farthest a convex corner of the design may be from the bead's axis: where the
  // shrunk section's corner lies farther, it moves out along the corner's bisector until it
  // is this far. A round bead along a corner half a bead in falls short of the corner
  // itself (0.21 mm for a 1.2 mm bead at a right angle, 0.05 mm in); where that is more
  // than the tolerance leaves, the bead rather stands a little past the faces beside the
  // corner, which a cutter can take off and nothing can add. Infinite: the corners stay.
  double corner_reach = 0;
  // Polylines shorter than this are dropped.
  double min_length = 0;
};

// A layer's contour: the lines on the exact section, the voxel chains left, and the cells
// the exact lines run through (where the rasters are to meet them).
struct NearNetContour {
  std::vector<std::vector<Point2>> exact, voxel;
  SliceMask exact_cells;
};

// `axes`: where the layer's bead axes may go (section_shrunk); `region`: the layer's cells
// (a loop point counts as over the region where the cell holding it is set);
// `voxel_chains`: the voxel contour (voxel_contour). A loop kept whole is closed (its first
// point repeated at its end). Unlike the voxel contour's, a bead on the exact section may
// hold the centre of a cell just past the design's face: it stands there within the
// slack, and the part is judged on the STL (docs/toolpaths.md).
NearNetContour near_net_contour(const TipKeepOut& axes, const SliceMask& region,
                                const std::vector<std::vector<Point2>>& voxel_chains, const geometry::Lattice& lattice,
                                const NearNetBead& bead);

// Between the beads on a thin wall's two faces, farther apart than a bead, rasters only
// cross (the B-axis machine's 1.2 mm bead on a 2.5 mm blade leaves 0.15 mm, and the
// rasters across the blade stop short of its ends): the loops half a bead inside the axes
// where what lies between them is narrower than `hatch_spacing`, over the region's cells.
std::vector<std::vector<Point2>> near_net_gap_loops(const TipKeepOut& axes, const SliceMask& region,
                                                    const geometry::Lattice& lattice, const NearNetBead& bead,
                                                    double hatch_spacing);

// The heights (mm) whose sections a near-net layer's contour follows, the layer laid at
// `zb` (the bead's bottom) `layer_height` thick: the middle of the height over which the
// bead is full width (instruments/bead.hpp), so that on a sloped face the layer's
// staircase straddles the face rather than standing out of it by a layer's step. Where a
// flat face of `design` lies within the layer, the layer holds the part above or below it
// only, as its voxels do: there the sections at the voxel centres within the layer.
std::vector<double> near_net_section_heights(const std::vector<geometry::Triangle>& design, double zb,
                                             double layer_height, double bead_height, const geometry::Lattice& lattice);

// The loop (region on its right, as TipKeepOut's) with each convex corner whose design
// corner lies farther than `bead.corner_reach` from it replaced by a detour: along the
// incoming side to a little before it, out along its bisector until the design's corner is
// that far, and back onto the outgoing side.
std::vector<Point2> corners_reaching(const std::vector<Point2>& loop, const NearNetBead& bead);

}  // namespace hybridctl::toolpaths
