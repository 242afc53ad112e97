#pragma once
// The design's cross-sections and shadows as Clipper (libpolyclipping) polygons on integer
// coordinates, and their offsets with round joins: the planar geometry wall finishing
// (toolpaths/wall_finish.hpp) and the corner reach proof (toolpaths/corner_reach.hpp) cut
// out of the STL's triangles. Included only by the .cpp files that use Clipper.

#include <clipper.hpp>

#include <cmath>
#include <vector>

#include "geometry/mesh.hpp"

namespace hybridctl::toolpaths::sections {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

// Integer units per mm: 10 nm, far below every tolerance; coordinates up to ~1e8 units
// stay in Clipper's 64-bit range with room to spare.
constexpr double kScale = 1e5;

inline cInt to_units(double mm) { return cInt(std::llround(mm * kScale)); }
inline double to_mm(cInt u) { return double(u) / kScale; }

// The union of closed polygons under `fill`.
Paths union_of(const Paths& polys, ClipperLib::PolyFillType fill);

// The cross-section of the closed solid bounded by `design` at Z = h: the points an odd
// number of facets lie over (or, the same for a closed surface, under: whichever side has
// fewer facets). At a plane that holds facets the two differ by those facets; the shadow
// adds them anyway. Empty at an infinite h.
Paths cross_section(const std::vector<geometry::Triangle>& design, double h);

// The design within lo <= Z <= hi seen from above: its cross-section at lo and every
// facet that is not vertical, clipped to the slab.
Paths shadow(const std::vector<geometry::Triangle>& design, double lo, double hi);

// Closed polygons grown (shrunk, for a negative `delta`) by `delta` mm with round joins
// whose chords lie at most `chord_tolerance` mm inside their arcs.
Paths offset(const Paths& polys, double delta, double chord_tolerance);

}  // namespace hybridctl::toolpaths::sections
