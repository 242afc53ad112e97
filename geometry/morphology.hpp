#pragma once
// Morphology on voxel solids: Minkowski sum (dilation) and difference (erosion) with the
// structuring elements that describe beads, cutters, shanks, holders and the "shadow"
// of an infinite shank.
//
// Every element is turned into a set of voxel offsets on the solid's lattice: offset
// d belongs to the element when the point d * voxel_size (the offset between two voxel
// centres) lies in the shape. dilate(S, B) = { s + d : s in S, d in B }. The fast paths
// (distance transforms, column sweeps) compute exactly that set, voxel for voxel; the
// FFT convolution and the brute-force sum compute it for any offset set and serve as
// oracles in the tests.

#include <functional>
#include <limits>
#include <variant>
#include <vector>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {

// A direction along one lattice axis: sign +1 or -1.
struct AxisDirection {
  Axis axis = Axis::Z;
  int sign = +1;
  AxisDirection reversed() const { return {axis, -sign}; }
  friend bool operator==(const AxisDirection&, const AxisDirection&) = default;
};

struct Ball {
  double radius = 0;  // mm
};

struct Ellipsoid {
  Vec3 radii;  // mm, along X, Y, Z
};

// One piece of an axisymmetric body, from `from` to `to` mm along its axis (closed
// interval; `to` may be infinite for a shank that never ends).
struct AxialSection {
  enum class Kind {
    Cylinder,  // radius `radius`
    Sphere,    // the zone of a sphere of radius `radius` centred at `centre` on the axis
    Torus,     // ring radius `ring` plus a tube of radius `radius` centred at `centre`
  };
  Kind kind = Kind::Cylinder;
  double from = 0, to = 0;
  double radius = 0;
  double centre = 0;
  double ring = 0;

  // The section's radius at `z` mm along the axis, squared; negative outside it.
  double radius_squared_at(double z) const;
};

// A body of revolution about a lattice axis, starting at the origin and extending in
// `direction`: a cutter with its shank and holder, a cylindrical bead, a ray (radius 0).
struct AxialBody {
  AxisDirection direction;
  std::vector<AxialSection> sections;
};

// Any set of offsets, in voxels.
struct VoxelOffsets {
  std::vector<Index3> offsets;
};

using StructuringElement = std::variant<Ball, Ellipsoid, AxialBody, VoxelOffsets>;

// Common bodies.
AxialBody cylinder_body(AxisDirection direction, double radius, double length);
// Radius 0, infinite length: dilating by it casts the shadow of a solid along `direction`.
AxialBody ray_body(AxisDirection direction);
// The point reflection -B of an element.
StructuringElement reflected(const StructuringElement& element);

// The element's offsets on a lattice of voxel size `voxel_size`. Infinite bodies are
// cut at `max_length_voxels` along their axis.
std::vector<Index3> offsets_of(const StructuringElement& element, double voxel_size, int max_length_voxels = 0);

enum class MorphologyMethod {
  Auto,               // the fastest exact method for the element (see below)
  DistanceTransform,  // separable squared-distance transforms: balls, ellipsoids, axial bodies
  Shifts,             // union of shifted copies, 64 voxels a word; any finite element
  Fft,                // convolution of indicator functions with FFTW; any finite element
  BruteForce,         // the definition, for tests on small grids
};

// Auto picks Shifts for elements of at most kShiftOffsetLimit offsets (small beads and
// balls: measured faster than the transforms, bench/morphology_bench), distance
// transforms for larger balls, ellipsoids and every axial body, FFT for other large sets.
inline constexpr std::size_t kShiftOffsetLimit = 400;

// Dilation S (+) B, clipped to `domain` (needed for infinite elements; pass an empty box
// for "wherever the result reaches", finite elements only).
Solid dilate(const Solid& solid, const StructuringElement& element, const IndexBox& domain = {},
             MorphologyMethod method = MorphologyMethod::Auto);
// The dilations of one solid by several elements, each clipped to `domain`: axial bodies
// along the same axis share one distance transform across it (a cutter, its shank and
// holder, and every other tool from the same side).
std::vector<Solid> dilate_each(const Solid& solid, const std::vector<StructuringElement>& elements, const IndexBox& domain);
// Where an axial tool sweeps without its clearance meeting the solid: the voxels of
// `domain` that the cutting part B covers at some position p (its tip) where none of the
// clearance bodies, placed at p, meets the solid:
//   (complement of U_i (solid (+) -C_i)) (+) B,   within `domain`.
// No clearance bodies: the tip itself must lie outside the solid (C = {0}). Every body of
// a sweep shares the cutting part's axis and direction.
struct ToolSweep {
  AxialBody cutting;
  std::vector<AxialBody> clearance;
};
// Exact, voxel for voxel. When the clearance's union never narrows away from the tip and
// never ends (a cutter in its holder), the free tip positions in every column along the
// axis are one ray, so sweeps along one axis share one distance transform across it and
// the rest is work on heightmaps (morphology_columns.cpp); other clearances take the
// dilations above. Sweeps along the same axis share the work. `done(i)` reports sweep i.
std::vector<Solid> tool_sweeps(const Solid& solid, const std::vector<ToolSweep>& sweeps, const IndexBox& domain,
                               const std::function<void(std::size_t)>& done = {});
// Erosion S (-) B = { p : p + B inside S }, computed as the complement of the dilation
// of the complement by -B.
Solid erode(const Solid& solid, const StructuringElement& element, MorphologyMethod method = MorphologyMethod::Auto);
// Opening (S (-) B) (+) B and closing (S (+) B) (-) B with the same element.
Solid open(const Solid& solid, const StructuringElement& element, MorphologyMethod method = MorphologyMethod::Auto);
Solid close(const Solid& solid, const StructuringElement& element, MorphologyMethod method = MorphologyMethod::Auto);

// Stands for "no end" in element extents.
inline constexpr int kUnboundedExtent = 1 << 28;

// The half-open box of the element's offsets, in voxels. An infinite body reaches
// kUnboundedExtent in its direction.
IndexBox element_extent(const StructuringElement& element, double voxel_size);

}  // namespace hybridctl::geometry

namespace hybridctl::geometry {

// The largest distance (mm, between voxel centres) from a voxel of `from` to the
// nearest voxel of `to`; 0 when `from` is empty, infinity when `to` is empty.
double farthest_distance(const Solid& from, const Solid& to);

}  // namespace hybridctl::geometry
