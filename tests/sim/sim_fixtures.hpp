#pragma once
// Shared instruments and brute-force oracles for the material simulation tests.

#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "geometry/morphology.hpp"
#include "geometry/solid.hpp"
#include "sim/instrument.hpp"
#include "sim/sweep.hpp"

namespace hybridctl::sim::testing {

using geometry::AxialSection;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;
using Kind = AxialSection::Kind;

// Voxel i has its centre at 0.5 * i mm: tool positions on voxel centres are easy to write.
inline const Lattice kLattice{0.5, {-0.25, -0.25, -0.25}};

inline std::vector<AxialSection> flat_mill(double r = 2.0, double flute = 3.0) {
  return {{Kind::Cylinder, 0, flute, r, 0, 0}};
}
inline std::vector<AxialSection> ball_mill(double r = 1.5, double flute = 3.5) {
  return {{Kind::Sphere, 0, r, r, r, 0}, {Kind::Cylinder, r, flute, r, 0, 0}};
}
inline std::vector<AxialSection> bull_mill(double r = 1.75, double corner = 0.75, double flute = 3.0) {
  return {{Kind::Torus, 0, corner, corner, corner, r - corner}, {Kind::Cylinder, corner, flute, r, 0, 0}};
}
// A finite shank and holder above a 3 mm flute.
inline std::vector<AxialSection> shank_and_holder() {
  return {{Kind::Cylinder, 3.0, 4.0, 0.75, 0, 0}, {Kind::Cylinder, 4.0, 5.0, 2.5, 0, 0}};
}

// Inside test of a shape in the instrument frame (q relative to the programmed point).
using ShapeTest = std::function<bool(double qx, double qy, double qz)>;

// Axial sections grown by `delta` mm (negative: shrunk): radii, tubes and slabs.
inline ShapeTest sections_shape(std::vector<AxialSection> sections, double delta = 0) {
  for (AxialSection& s : sections) {
    s.radius += delta;
    s.from -= delta;
    s.to += delta;
  }
  return [sections](double qx, double qy, double qz) {
    const double rho2 = qx * qx + qy * qy;
    for (const AxialSection& s : sections)
      if (s.radius >= 0 && s.radius_squared_at(qz) >= rho2) return true;
    return false;
  };
}

// An ellipsoid bead anchored at its bottom, with the cylinder of its width below its
// widest line (the bead fills the valleys it is laid in), grown by `delta`.
inline ShapeTest ellipsoid_bead_shape(double width, double height, double delta = 0) {
  const double a = width / 2 + delta, b = height / 2 + delta, c = height / 2;
  return [=](double qx, double qy, double qz) {
    const double rho2 = qx * qx + qy * qy;
    if (qz >= -delta && qz <= c && rho2 <= a * a) return true;
    return rho2 / (a * a) + (qz - c) * (qz - c) / (b * b) <= 1;
  };
}

// The union of the shape placed at `positions`, over `domain`; `reach` bounds the shape:
// |qx|, |qy| <= reach and qz in [zlo, zhi].
inline Solid placed_union(const ShapeTest& inside, const std::vector<geometry::Vec3>& positions, double reach,
                          double zlo, double zhi, const IndexBox& domain, const Lattice& lattice = kLattice) {
  Solid out(lattice, domain);
  for (const geometry::Vec3& s : positions) {
    const IndexBox box = geometry::box_intersection(
        lattice.centers_within({{s.x - reach, s.y - reach, s.z + zlo}, {s.x + reach, s.y + reach, s.z + zhi}}), domain);
    for (int z = box.lo.z; z < box.hi.z; ++z)
      for (int y = box.lo.y; y < box.hi.y; ++y)
        for (int x = box.lo.x; x < box.hi.x; ++x) {
          const geometry::Vec3 c = lattice.center({x, y, z});
          if (inside(c.x - s.x, c.y - s.y, c.z - s.z)) out.set({x, y, z});
        }
  }
  return out;
}

// n + 1 evenly spaced points from a to b.
inline std::vector<geometry::Vec3> samples(geometry::Vec3 a, geometry::Vec3 b, int n) {
  std::vector<geometry::Vec3> out;
  for (int i = 0; i <= n; ++i) {
    const double t = double(i) / n;
    out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z)});
  }
  return out;
}

inline double distance(geometry::Vec3 a, geometry::Vec3 b) {
  return std::hypot(b.x - a.x, b.y - a.y, b.z - a.z);
}

// a is a subset of b.
inline bool subset(const Solid& a, const Solid& b) { return geometry::subtract(a, b).empty(); }

}  // namespace hybridctl::sim::testing
