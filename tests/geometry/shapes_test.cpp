// Analytic shapes hold the voxels whose centres they contain, so their volumes
// converge to the exact ones.

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/shapes.hpp"

namespace hybridctl::geometry {
namespace {

TEST(Shapes, ABoxOnVoxelBoundariesIsExact) {
  const Solid box = make_box({0.5, {0, 0, 0}}, {{1, 2, 3}, {11, 7, 4.5}});
  EXPECT_DOUBLE_EQ(box.volume(), 10 * 5 * 1.5);
  EXPECT_EQ(box.bounding_box(), (IndexBox{{2, 4, 6}, {22, 14, 9}}));
}

TEST(Shapes, SphereVolumeConvergesWithVoxelSize) {
  const double r = 10, exact = 4.0 / 3.0 * M_PI * r * r * r;
  const double coarse = make_sphere({1.0, {0, 0, 0}}, {0.3, 0.1, 0.2}, r).volume();
  const double fine = make_sphere({0.25, {0, 0, 0}}, {0.3, 0.1, 0.2}, r).volume();
  EXPECT_NEAR(fine, exact, 0.005 * exact);
  EXPECT_LT(std::abs(fine - exact), std::abs(coarse - exact) + 1e-9);
}

TEST(Shapes, EllipsoidAndCylinderVolumes) {
  const Lattice l{0.25, {0, 0, 0}};
  const double ellipsoid = 4.0 / 3.0 * M_PI * 12 * 6 * 4;
  EXPECT_NEAR(make_ellipsoid(l, {0, 0, 0}, {12, 6, 4}).volume(), ellipsoid, 0.01 * ellipsoid);
  const double cylinder = M_PI * 5 * 5 * 20;
  for (Axis axis : {Axis::X, Axis::Y, Axis::Z}) {
    EXPECT_NEAR(make_cylinder(l, axis, {1, 2, 3}, 5, 20).volume(), cylinder, 0.01 * cylinder);
  }
}

TEST(Shapes, CylinderAxesAreRotationsOfEachOther) {
  const Lattice l{1.0, {0, 0, 0}};
  // A Z cylinder from the origin turned +90 degrees about X points along -Y.
  const Solid z = make_cylinder(l, Axis::Z, {0, 0, 0}, 4, 10);
  const Solid y = make_cylinder(l, Axis::Y, {0, -10, 0}, 4, 10);
  EXPECT_EQ(rotate_quarter_turns(z, Axis::X, 1), y);
}

TEST(Shapes, NonPositiveSizesAreRefused) {
  const Lattice l{1.0, {0, 0, 0}};
  EXPECT_THROW(make_sphere(l, {0, 0, 0}, 0), std::invalid_argument);
  EXPECT_THROW(make_cylinder(l, Axis::Z, {0, 0, 0}, 1, -2), std::invalid_argument);
  EXPECT_THROW(Solid({0.0, {0, 0, 0}}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace hybridctl::geometry
