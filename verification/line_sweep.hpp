#pragma once
// Where a straight line meets the volume an instrument sweeps along a straight segment:
// the exact geometry under the point-vector verification (verification/exact_deviation.hpp).
//
// An instrument is a union of convex pieces of revolution about +Z (sim::ConvexPiece: the
// one definition the material simulation sweeps). A convex piece moved along a segment
// sweeps a convex volume (the Minkowski sum of the piece and the segment), so a line meets
// it in one interval of its parameter. That interval is computed:
//  - in closed form for a cylinder moved level or along its axis (a 2D capsule or disc in
//    XY within a Z slab), for a cylinder on a ramp (the extremes of a convex region of the
//    line's and the segment's parameters: half-planes and one quadratic), and for a whole
//    sphere or ellipsoid moved in any direction (a 3D capsule, the ellipsoid's after
//    scaling Z);
//  - otherwise (a torus off the level and the vertical, a sphere cut by its slab) as the sublevel
//    set {g <= 0} of the convex function g(t) = min over the segment of the piece's convex
//    gauge at the line's point: bisection for the two ends, to about 1e-9 mm, from a point
//    inside (an end of the stretch asked about, a point of a coarse scan, or else the
//    minimum, found by golden-section search).

#include <span>
#include <vector>

#include "geometry/solid.hpp"
#include "sim/sweep.hpp"

namespace hybridctl::verification {

// A closed interval of a line's parameter (mm along a unit direction); empty when lo > hi.
struct Span {
  double lo = 1, hi = 0;
  bool empty() const { return !(lo <= hi); }
};

// The parameters t in [t0, t1] for which p + t d lies in the volume `piece` sweeps when
// its programmed point moves along `segment` (work frame, piece axis +Z). `d` need not be
// unit; the result is in units of t.
Span line_in_sweep(const sim::ConvexPiece& piece, const sim::Segment& segment, const geometry::Vec3& p,
                   const geometry::Vec3& d, double t0, double t1);

// The pieces of an instrument with every sphere or torus that a cylinder of its own
// reach continues upwards from its centre made whole: the same union (the upper half lies
// in the cylinder), and one that line_in_sweep answers in closed form for a ball cutter.
std::vector<sim::ConvexPiece> completed_pieces(std::span<const sim::ConvexPiece> pieces);

}  // namespace hybridctl::verification
