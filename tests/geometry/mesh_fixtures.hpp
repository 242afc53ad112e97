#pragma once
// Small meshes with known volumes, built in code so tests say exactly what they hold.

#include <cmath>
#include <vector>

#include "geometry/mesh.hpp"

namespace hybridctl::geometry::testing {

// An axis-aligned box as 12 outward-oriented triangles.
inline TriangleMesh box_mesh(Vec3 lo, Vec3 hi) {
  const Vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                     {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  TriangleMesh m;
  for (const auto& f : faces) {
    m.triangles.push_back({p[f[0]], p[f[1]], p[f[2]]});
    m.triangles.push_back({p[f[0]], p[f[2]], p[f[3]]});
  }
  return m;
}

// A UV sphere approximation: closed, outward, `rings` x `segments` facets.
inline TriangleMesh sphere_mesh(Vec3 c, double r, int rings = 24, int segments = 48) {
  auto at = [&](int i, int j) {
    const double theta = M_PI * i / rings, phi = 2 * M_PI * (j % segments) / segments;
    if (i == 0) return Vec3{c.x, c.y, c.z + r};
    if (i == rings) return Vec3{c.x, c.y, c.z - r};
    return Vec3{c.x + r * std::sin(theta) * std::cos(phi), c.y + r * std::sin(theta) * std::sin(phi),
                c.z + r * std::cos(theta)};
  };
  TriangleMesh m;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const Vec3 a = at(i, j), b = at(i + 1, j), d = at(i, j + 1), e = at(i + 1, j + 1);
      if (i != 0) m.triangles.push_back({a, b, d});
      if (i != rings - 1) m.triangles.push_back({d, b, e});
    }
  return m;
}

// A convex polygon (counter-clockwise, x and y of each point) extruded from z0 to z1:
// closed and outward-oriented.
inline TriangleMesh prism_mesh(const std::vector<Vec3>& polygon, double z0, double z1) {
  TriangleMesh m;
  const std::size_t n = polygon.size();
  const auto at = [&](std::size_t i, double z) { return Vec3{polygon[i % n].x, polygon[i % n].y, z}; };
  for (std::size_t i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({at(0, z0), at(i + 1, z0), at(i, z0)});
    m.triangles.push_back({at(0, z1), at(i, z1), at(i + 1, z1)});
  }
  for (std::size_t i = 0; i < n; ++i) {
    m.triangles.push_back({at(i, z0), at(i + 1, z0), at(i + 1, z1)});
    m.triangles.push_back({at(i, z0), at(i + 1, z1), at(i, z1)});
  }
  return m;
}

// A bar `width` wide from `from` to `to` (x and y), standing from z0 to z1.
inline TriangleMesh bar_mesh(Vec3 from, Vec3 to, double width, double z0, double z1) {
  const double len = std::hypot(to.x - from.x, to.y - from.y);
  const double nx = -(to.y - from.y) / len * width / 2, ny = (to.x - from.x) / len * width / 2;
  return prism_mesh({{from.x - nx, from.y - ny, 0}, {to.x - nx, to.y - ny, 0}, {to.x + nx, to.y + ny, 0},
                     {from.x + nx, from.y + ny, 0}},
                    z0, z1);
}

inline TriangleMesh joined(TriangleMesh a, const TriangleMesh& b) {
  a.triangles.insert(a.triangles.end(), b.triangles.begin(), b.triangles.end());
  return a;
}

}  // namespace hybridctl::geometry::testing
