#pragma once
// Closed meshes with known surfaces for the verification tests.

#include <cmath>
#include <numbers>

#include "geometry/mesh.hpp"

namespace hybridctl::verification::testing {

using geometry::TriangleMesh;
using geometry::Vec3;

// A box [lo, hi], outward winding (or inward, turned).
inline TriangleMesh box_mesh(Vec3 lo, Vec3 hi, bool turned = false) {
  const Vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                     {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  TriangleMesh m;
  for (const auto& t : f) m.triangles.push_back(turned ? geometry::Triangle{c[t[0]], c[t[2]], c[t[1]]}
                                                       : geometry::Triangle{c[t[0]], c[t[1]], c[t[2]]});
  return m;
}

// A cylinder about Z through (cx, cy), z in [z0, z1], as an n-gon (vertices on the circle).
inline TriangleMesh cylinder_mesh(double cx, double cy, double r, double z0, double z1, int n) {
  TriangleMesh m;
  auto at = [&](int k, double z) {
    const double a = 2 * std::numbers::pi * k / n;
    return Vec3{cx + r * std::cos(a), cy + r * std::sin(a), z};
  };
  const Vec3 bottom{cx, cy, z0}, top{cx, cy, z1};
  for (int k = 0; k < n; ++k) {
    const Vec3 a0 = at(k, z0), b0 = at(k + 1, z0), a1 = at(k, z1), b1 = at(k + 1, z1);
    m.triangles.push_back({a0, b0, b1});
    m.triangles.push_back({a0, b1, a1});
    m.triangles.push_back({bottom, b0, a0});
    m.triangles.push_back({top, a1, b1});
  }
  return m;
}

}  // namespace hybridctl::verification::testing
