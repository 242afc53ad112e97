#pragma once
// Exact contour finishing of walls (docs/toolpaths.md, "Wall finishing"): at one tip
// height, the tip positions where a tool would cut into the design, computed from the
// design's triangles (the STL, not its voxels), and the boundary of that region: the
// closed paths on which the tool's side is tangent to the design's walls.
//
//   TipKeepOut f = tip_keep_out(design, z, flat_tool_bands(tool));
//   for (const auto& loop : f.loops()) ...   // finishing paths, climb direction
//
// The tool is a body of revolution about +Z given as bands: radius r_i over
// [from_i, to_i] mm above the tip (a flat cutter over its flute length, the shank above
// it, the holder above that, to = infinity). Everything is in the work frame (the tool
// axis is +Z), in mm.
//
// Construction, per band: the design within the slab z + from_i <= Z <= z + to_i
// projected onto XY (its shadow: the design's cross-section at the slab's bottom plane,
// by even-odd crossings of the facets on one side of it, plus every facet that is not
// vertical clipped to the slab), offset by r_i with round joins (Clipper, integer
// coordinates of 10 nm); the union over the bands is the keep-out region. A point outside
// it puts no part of the tool into the design: a vertical facet inside a slab is covered
// by the facet under it or by the cross-section (go down the facet until either). The
// bands start `floor_slack` above their bottoms: a face at the tip's own height is a
// floor the flat bottom stands on, not a wall, and a face at the height where a wider
// section begins (the top of a wall as tall as the flutes, under the shank) is touched,
// not entered (the band below holds it).
//
// Accuracy: each band is offset by r_i + chord_tolerance + clearance, and a round join's
// chords lie at most chord_tolerance inside its arc, so every point of a loop is between
// r_i + clearance and r_i + chord_tolerance + clearance (plus 10 nm of rounding) from the
// nearest band's shadow: the tool stands off the design by at least `clearance` (which
// covers G-code's 0.0001 mm and the integer rounding) and by at most about
// chord_tolerance + clearance where that band is the one that limits it.

#include <utility>
#include <vector>

#include "config/machine.hpp"
#include "geometry/mesh.hpp"
#include "toolpaths/point2.hpp"
#include "toolpaths/slices.hpp"

namespace hybridctl::toolpaths {

// Radius `radius` over [from, to] mm above the tip; `to` may be infinity.
struct ToolBand {
  double from = 0, to = 0, radius = 0;
};

struct WallFinishOptions {
  // The largest distance (mm) of a round join's chord inside its arc.
  double chord_tolerance = 0.001;
  // Added to every band's radius (mm): the least stand-off from the design.
  double clearance = 0.0002;
  // Every band starts this far (mm) above its bottom.
  double floor_slack = 0.0001;
};

// A region of tip positions at one height (a union of polygons, mm), with its boundary.
class TipKeepOut {
 public:
  TipKeepOut() = default;
  // Loops as Clipper makes them: region on the left of each (outer loops counter-clockwise).
  explicit TipKeepOut(std::vector<std::vector<Point2>> loops_region_on_left);

  bool empty() const { return loops_.empty(); }
  // The boundary: closed loops (the first point is not repeated), each with the region on
  // its right, so that a right-hand cutter (M3) following it climb-mills the wall:
  // clockwise round an island, counter-clockwise inside a pocket.
  const std::vector<std::vector<Point2>>& loops() const { return loops_; }

  // Inside the region (even-odd over the loops); a point within 1e-7 mm of the
  // boundary counts as inside.
  bool contains(Point2 p) const;
  // No point of the segment a-b lies in the region's interior (it may touch the
  // boundary, e.g. end on a loop). Exact up to rounding: the segment is cut where it meets
  // the loops and each piece is tested at its middle.
  bool segment_clear(Point2 a, Point2 b) const;
  // The region grown by `by` mm (round joins; chords at least `by` from it).
  TipKeepOut grown(double by, double chord_tolerance = 0.001) const;
  // The pieces of the segment a-b that lie in the region (its boundary included), in
  // order from a; none where it runs outside only.
  std::vector<std::pair<Point2, Point2>> pieces_inside(Point2 a, Point2 b) const;
  // The point of the boundary nearest p; p itself when there is no boundary.
  Point2 nearest_on_boundary(Point2 p) const;

 private:
  // Where the segment a-b meets the loops, as parameters along it, sorted, 0 and 1 included.
  std::vector<double> meeting_parameters(Point2 a, Point2 b) const;
  std::vector<std::vector<Point2>> loops_;  // region on the right
};

// The tip positions at height `tip_z` where a tool of `bands` would cut into the solid
// bounded by `design` (closed; duplicate facets removed: geometry::clean_mesh).
TipKeepOut tip_keep_out(const std::vector<geometry::Triangle>& design, double tip_z, const std::vector<ToolBand>& bands,
                        const WallFinishOptions& options = {});

// The union of the design's cross-sections at `heights`, shrunk by `inset` mm (round
// joins): where the axis of a bead `inset` wide on either side keeps its whole width inside
// the design at one of those heights (a near-net deposit's layer, from its bottom to its
// top). Not a keep-out: the region is where the axis may go.
TipKeepOut section_shrunk(const std::vector<geometry::Triangle>& design, const std::vector<double>& heights,
                          double inset, double chord_tolerance = 0.001);

// The cells of `window` whose centres lie inside `region` or on its edge (even-odd over its
// loops), row by row where each row's line through the centres crosses the loops: a
// near-net layer's cells that its beads reach, a pocket's cells within a keep-out region.
SliceMask cells_inside(const TipKeepOut& region, const SliceMask& window, const geometry::Lattice& lattice);

// A flat end mill's bands (its defaults applied: instruments::with_defaults): the cutter
// over [0, flute], the shank over [flute, flute + shank length], the holder above; each as
// wide as the tool is anywhere below it, so that the region also keeps vertical moves
// (plunges, retracts) out of the design. Empty for a ball or bull nose.
std::vector<ToolBand> flat_tool_bands(const config::CuttingTool& tool);

}  // namespace hybridctl::toolpaths
