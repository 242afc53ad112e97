#pragma once
// Exact swept volumes of convex bodies of revolution moved along a straight segment, at
// voxel resolution: a voxel belongs to the sweep iff its centre lies in the body placed
// at some point of the segment (closed shapes; a centre within kTieSlack voxels of the
// boundary counts as inside, so exact ties are inside as in geometry's shapes).
//
// Every instrument is a union of convex pieces (ConvexPiece). The sweep of a convex piece
// meets each lattice row (fixed y, z) in one interval, computed per row, not per voxel:
//  - the piece's slab along its axis fixes, for the row's z, the sub-segment of positions
//    that can reach the row;
//  - over that sub-segment a cylinder sweeps a 2D capsule (disc swept along the XY
//    projection), a sphere a 3D capsule, an ellipsoid a 3D capsule after scaling Z:
//    closed forms, exact for any direction (horizontal, vertical, ramps);
//  - a torus (bull-nose corner) sweeps a 2D capsule for horizontal and vertical moves
//    (exact); on ramps the interval lies between the capsules of its smallest and
//    largest radius over the sub-segment, and the voxels in between are decided one by
//    one by minimising the distance to the torus's core disc over the sub-segment
//    (convex in the position; bisection on the derivative to machine precision).
// So the result is the definition, up to floating-point rounding (~1e-12 mm), for every
// piece and every segment. Cost: O(rows of the bounding box) closed forms per piece.

#include <span>
#include <vector>

#include "geometry/solid.hpp"
#include "sim/instrument.hpp"

namespace hybridctl::sim {

using geometry::Vec3;

// A voxel centre this close to the swept boundary (in voxels) counts as inside.
inline constexpr double kTieSlack = 1e-6;

// One convex piece of an instrument in its own frame: programmed point at the origin,
// axis +Z. Every piece is a solid of revolution cut to the slab z in [from, to].
struct ConvexPiece {
  enum class Kind {
    Cylinder,   // radius `radius`; `to` may be infinite
    Sphere,     // ball of radius `radius` centred at height `centre`
    Torus,      // points within `radius` of the horizontal disc of radius `ring` at `centre`
    Ellipsoid,  // semi-axes `radius` across, `half_height` along the axis, centre at `centre`
  };
  Kind kind = Kind::Cylinder;
  double from = 0, to = 0;  // mm along the axis; within the shape's own extent
  double radius = 0;
  double centre = 0;
  double ring = 0;
  double half_height = 0;

  // The largest distance of the piece from its axis, mm.
  double reach() const;
};

// The convex pieces of axial sections (sections with from > to are empty and dropped).
// Throws std::invalid_argument for a negative or non-finite radius or an infinite
// non-cylinder section.
std::vector<ConvexPiece> pieces_of(std::span<const geometry::AxialSection> sections);
// The bead's shape (its body is not included): a cylinder bead as one piece, an
// ellipsoid bead as the ellipsoid and, below its widest line, the cylinder of its width
// (the bead fills the valleys it is laid in). Throws
// std::invalid_argument unless width and height are positive.
std::vector<ConvexPiece> pieces_of(const Bead& bead);

// The straight path of the programmed point, mm.
struct Segment {
  Vec3 from, to;
};

// A half-open range [x0, x1) of voxel X indices.
struct XRange {
  int x0 = 0, x1 = 0;
  bool empty() const { return x1 <= x0; }
};

// The sweep of one piece along one segment on one lattice, row by row.
class PieceSweep {
 public:
  PieceSweep(const ConvexPiece& piece, const Segment& segment, const geometry::Lattice& lattice);

  // The voxels that may be swept (half-open), intersected with `clip`. An infinite piece
  // needs a non-empty clip (std::invalid_argument otherwise).
  geometry::IndexBox bounds(const geometry::IndexBox& clip = {}) const;
  // The swept voxels of row (y, z).
  XRange row(int y, int z) const;
  // Whether row(y, z) is one interval per y at every height the slab covers: a cylinder
  // moved level or straight along its axis. Only the bounds' first and last heights,
  // where the slab's edge falls, may differ from the rest.
  bool alike_in_height() const { return piece_.kind == ConvexPiece::Kind::Cylinder && (level_ || vertical_); }

 private:
  bool torus_contains(double x, double y, double z, double ta, double tb) const;
  XRange to_voxels(double lo, double hi) const;

  ConvexPiece piece_;
  Vec3 a_, b_, d_;
  double h_, slack_;
  geometry::Vec3 origin_;
  bool level_ = false;     // dz == 0
  bool vertical_ = false;  // dx == dy == 0
};

// The voxels of `domain` swept by the union of `pieces` along `segment`.
geometry::Solid swept_volume(std::span<const ConvexPiece> pieces, const Segment& segment,
                             const geometry::Lattice& lattice, const geometry::IndexBox& domain);

}  // namespace hybridctl::sim
