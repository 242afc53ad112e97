// The design's surface as verification samples it: outward normals whatever the winding,
// the area shared out, vectors that stop halfway to the next face.
#include "verification/design_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>

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
