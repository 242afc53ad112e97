// The work frame of a setup: the part frame turned by quarter turns so that the approach
// direction becomes +Z, about the part origin; points, voxel indices, boxes and solids
// all turn the same way.

#include "toolpaths/setup_frame.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/shapes.hpp"

namespace hybridctl::toolpaths {
namespace {

using config::Approach;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::Solid;
using geometry::Vec3;

constexpr Approach kAll[] = {Approach::PlusX, Approach::MinusX, Approach::PlusY,
                             Approach::MinusY, Approach::PlusZ, Approach::MinusZ};

void expect_near(Vec3 a, Vec3 b) {
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
}

double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

TEST(SetupFrame, TheApproachDirectionBecomesPlusZ) {
  for (Approach a : kAll) {
    SCOPED_TRACE(std::string(config::to_string(a)));
    expect_near(part_to_work(approach_vector(a), a), {0, 0, 1});
    expect_near(work_to_part({0, 0, 1}, a), approach_vector(a));
  }
}

TEST(SetupFrame, PlusZIsThePartFrame) {
  expect_near(part_to_work(Vec3{1.5, -2, 3.25}, Approach::PlusZ), {1.5, -2, 3.25});
}

TEST(SetupFrame, TurnsAreRotationsAboutTheOriginAndInvertible) {
  const Vec3 ex{1, 0, 0}, ey{0, 1, 0}, p{3, -4, 7};
  for (Approach a : kAll) {
    SCOPED_TRACE(std::string(config::to_string(a)));
    expect_near(work_to_part(part_to_work(p, a), a), p);
    expect_near(part_to_work({0, 0, 0}, a), {0, 0, 0});
    // Right-handed: x cross y stays z after turning.
    const Vec3 wx = part_to_work(ex, a), wy = part_to_work(ey, a);
    expect_near(cross(wx, wy), part_to_work(Vec3{0, 0, 1}, a));
    EXPECT_NEAR(dot(part_to_work(p, a), part_to_work(p, a)), dot(p, p), 1e-9);
  }
}

TEST(SetupFrame, TheDocumentedTable) {
  const Vec3 p{1, 2, 3};
  expect_near(part_to_work(p, Approach::MinusZ), {1, -2, -3});
  expect_near(part_to_work(p, Approach::PlusX), {-3, 2, 1});
  expect_near(part_to_work(p, Approach::MinusX), {3, 2, -1});
  expect_near(part_to_work(p, Approach::PlusY), {1, -3, 2});
  expect_near(part_to_work(p, Approach::MinusY), {1, 3, -2});
}

TEST(SetupFrame, SolidsTurnLikeTheirVoxelCentres) {
  for (const Lattice lattice : {Lattice{0.5, {0, 0, 0}}, Lattice{0.5, {0.5, -1.0, 1.5}}, Lattice{0.5, {0.25, 0.25, 0.25}}}) {
    // An asymmetric L of boxes, away from the origin.
    Solid part = geometry::unite(geometry::make_box(lattice, {{1, 2, 3}, {4, 3, 5}}),
                                 geometry::make_box(lattice, {{1, 2, 3}, {2, 6, 4}}));
    for (Approach a : kAll) {
      SCOPED_TRACE(std::string(config::to_string(a)));
      const Solid work = part_to_work(part, a);
      EXPECT_EQ(work.voxel_count(), part.voxel_count());
      part.for_each_voxel([&](Index3 v) {
        const Index3 w = part_to_work(v, lattice, a);
        EXPECT_TRUE(work.contains(w));
        expect_near(lattice.center(w), part_to_work(lattice.center(v), a));
        EXPECT_EQ(work_to_part(w, lattice, a), v);
      });
      EXPECT_EQ(work_to_part(work, a), part);
      // The box of the turned voxels is the turned box.
      EXPECT_EQ(part_to_work(part.bounding_box(), lattice, a), work.bounding_box());
    }
  }
}

TEST(SetupFrame, ATurnThatMissesTheVoxelCentresIsRejected) {
  const Lattice odd{0.5, {0.1, 0, 0}};
  const Solid s = geometry::make_box(odd, {{1, 1, 1}, {2, 2, 2}});
  EXPECT_NO_THROW(part_to_work(s, Approach::PlusZ));
  EXPECT_NO_THROW(part_to_work(s, Approach::PlusY));  // turns about X leave x alone
  EXPECT_THROW(part_to_work(s, Approach::PlusX), std::invalid_argument);
  EXPECT_THROW(part_to_work(Index3{1, 1, 1}, odd, Approach::MinusX), std::invalid_argument);
}

}  // namespace
}  // namespace hybridctl::toolpaths
