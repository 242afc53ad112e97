// The design's surface as verification samples it: outward normals whatever the winding,
// the area shared out, vectors that stop halfway to the next face.
#include "verification/design_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "common/error.hpp"
#include "verification_meshes.hpp"

namespace hybridctl::verification {
namespace {

using testing::box_mesh;

SamplingOptions spacing(double s, double reach) {
  SamplingOptions o;
  o.spacing = s;
  o.reach = reach;
  return o;
}

TEST(DesignSurface, SamplesCoverTheAreaWithOutwardNormalsWhateverTheWinding) {
  for (const bool turned : {false, true}) {
    const DesignSurface surface(box_mesh({0, 0, 0}, {10, 8, 6}, turned), "box", spacing(0.5, 1));
    double area = 0;
    for (const SurfaceSample& s : surface.samples()) {
      area += s.area;
      // The normal points away from the box's centre.
      const double out = (s.point.x - 5) * s.normal.x + (s.point.y - 4) * s.normal.y + (s.point.z - 3) * s.normal.z;
      ASSERT_GT(out, 0) << "sample at (" << s.point.x << ", " << s.point.y << ", " << s.point.z << ")";
    }
    EXPECT_NEAR(area, 2 * (10 * 8 + 10 * 6 + 8 * 6), 1e-9);
    EXPECT_NEAR(surface.area(), area, 1e-9);
    EXPECT_GE(surface.samples().size(), 376u);  // at least one per spacing^2
  }
}

TEST(DesignSurface, EverySampleNamesTheFacetItWasCutFromAndTheFacetsShareItsArea) {
  geometry::TriangleMesh mesh = box_mesh({0, 0, 0}, {10, 8, 6});
  const std::size_t facets = mesh.triangles.size();
  mesh.triangles.push_back(mesh.triangles.front());                             // repeated: cleaned away
  mesh.triangles.push_back({geometry::Vec3{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});  // no area: skipped
  const DesignSurface surface(mesh, "box", spacing(0.5, 1));
  ASSERT_EQ(surface.triangles().size(), facets);
  std::vector<double> area(facets, 0);
  for (const SurfaceSample& s : surface.samples()) {
    ASSERT_LT(s.triangle, facets);
    const geometry::Triangle& t = surface.triangles()[s.triangle];
    // The sample lies on its facet: in its plane and inside its three edges.
    const auto sub = [](geometry::Vec3 a, geometry::Vec3 b) { return geometry::Vec3{a.x - b.x, a.y - b.y, a.z - b.z}; };
    const auto cross = [](geometry::Vec3 a, geometry::Vec3 b) {
      return geometry::Vec3{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    };
    const auto dot = [](geometry::Vec3 a, geometry::Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
    const geometry::Vec3 n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    EXPECT_NEAR(dot(sub(s.point, t[0]), n), 0, 1e-9);
    for (int e = 0; e < 3; ++e) EXPECT_GE(dot(cross(sub(t[(e + 1) % 3], t[e]), sub(s.point, t[e])), n), -1e-9);
    area[s.triangle] += s.area;
  }
  for (std::size_t i = 0; i < facets; ++i) {
    const geometry::Triangle& t = surface.triangles()[i];
    const double ax = t[1].x - t[0].x, ay = t[1].y - t[0].y, az = t[1].z - t[0].z;
    const double bx = t[2].x - t[0].x, by = t[2].y - t[0].y, bz = t[2].z - t[0].z;
    const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    EXPECT_NEAR(area[i], 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz), 1e-9) << "facet " << i;
  }
}

TEST(DesignSurface, AVectorStopsHalfwayToTheFaceBehindAThinWall) {
  // A wall 1 mm thick: inward vectors reach 0.5 mm, outward ones the whole reach.
  const DesignSurface surface(box_mesh({0, 0, 0}, {1, 20, 20}), "wall", spacing(0.5, 2));
  int checked = 0;
  for (const SurfaceSample& s : surface.samples()) {
    if (std::abs(s.normal.x) < 0.5 || s.point.y < 2 || s.point.y > 18 || s.point.z < 2 || s.point.z > 18) continue;
    EXPECT_NEAR(s.inward, 0.5, 1e-6);
    EXPECT_NEAR(s.outward, 2, 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(DesignSurface, MeasuresTheDistanceToTheNearestFace) {
  const DesignSurface surface(box_mesh({0, 0, 0}, {10, 10, 10}), "box", spacing(1, 1));
  EXPECT_NEAR(surface.distance({5, 5, 12}), 2, 1e-12);
  EXPECT_NEAR(surface.distance({5, 5, 9.5}), 0.5, 1e-12);
  EXPECT_NEAR(surface.distance({13, 14, 5}), 5, 1e-12);
}

TEST(DesignSurface, AMeshWithoutAreaIsAnInputErrorNamingIt) {
  geometry::TriangleMesh flat;
  flat.triangles.push_back({geometry::Vec3{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
  try {
    DesignSurface surface(flat, "flat.stl", spacing(1, 1));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("flat.stl"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hybridctl::verification
