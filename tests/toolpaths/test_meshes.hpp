#pragma once
// Closed meshes the toolpath tests build their cases from: prisms over polygons.

#include <cmath>
#include <numbers>
#include <vector>

#include "geometry/mesh.hpp"
#include "toolpaths/point2.hpp"

namespace hybridctl::toolpaths {

using Mesh = std::vector<geometry::Triangle>;

// A prism over a polygon that is star-shaped from its first vertex, z0..z1.
inline Mesh prism(const std::vector<Point2>& poly, double z0, double z1) {
  const auto at = [](Point2 p, double z) { return geometry::Vec3{p.x, p.y, z}; };
  Mesh m;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 a = poly[i], b = poly[(i + 1) % n];
    m.push_back({at(a, z0), at(b, z0), at(b, z1)});
    m.push_back({at(a, z0), at(b, z1), at(a, z1)});
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    m.push_back({at(poly[0], z0), at(poly[i + 1], z0), at(poly[i], z0)});
    m.push_back({at(poly[0], z1), at(poly[i], z1), at(poly[i + 1], z1)});
  }
  return m;
}

inline std::vector<Point2> rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

inline std::vector<Point2> regular(int n, double radius, Point2 c = {0, 0}) {
  std::vector<Point2> p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    p.push_back({c.x + radius * std::cos(a), c.y + radius * std::sin(a)});
  }
  return p;
}

}  // namespace hybridctl::toolpaths
