// Constructive solid geometry obeys the identities of set algebra, on analytic shapes
// that overlap in awkward ways (different storage boxes, word boundaries, negatives).

#include <gtest/gtest.h>

#include "geometry/shapes.hpp"
#include "geometry/solid.hpp"

namespace hybridctl::geometry {
namespace {

const Lattice kLattice{0.5, {0, 0, 0}};

struct Shapes {
  Solid a = make_sphere(kLattice, {0, 0, 0}, 12);
  Solid b = make_box(kLattice, {{-5, -20, -3}, {40, 4, 9}});
  Solid c = make_cylinder(kLattice, Axis::Y, {6, -15, 2}, 7, 30);
  Solid d = make_ellipsoid(kLattice, {-8, 3, 1}, {20, 5, 8});
  IndexBox domain = box_union(box_union(a.storage_box(), b.storage_box()), box_union(c.storage_box(), d.storage_box()));
};

TEST(Csg, UnionAndIntersectionCommuteAndAssociate) {
  Shapes s;
  EXPECT_EQ(unite(s.a, s.b), unite(s.b, s.a));
  EXPECT_EQ(intersect(s.a, s.b), intersect(s.b, s.a));
  EXPECT_EQ(unite(unite(s.a, s.b), s.c), unite(s.a, unite(s.b, s.c)));
  EXPECT_EQ(intersect(intersect(s.a, s.b), s.c), intersect(s.a, intersect(s.b, s.c)));
}

TEST(Csg, DistributiveLaws) {
  Shapes s;
  EXPECT_EQ(intersect(s.a, unite(s.b, s.c)), unite(intersect(s.a, s.b), intersect(s.a, s.c)));
  EXPECT_EQ(unite(s.a, intersect(s.b, s.c)), intersect(unite(s.a, s.b), unite(s.a, s.c)));
}

TEST(Csg, DeMorganWithinADomain) {
  Shapes s;
  EXPECT_EQ(complement(unite(s.a, s.d), s.domain), intersect(complement(s.a, s.domain), complement(s.d, s.domain)));
  EXPECT_EQ(complement(intersect(s.a, s.d), s.domain), unite(complement(s.a, s.domain), complement(s.d, s.domain)));
}

TEST(Csg, DifferenceIsIntersectionWithTheComplement) {
  Shapes s;
  EXPECT_EQ(subtract(s.a, s.c), intersect(s.a, complement(s.c, s.domain)));
  EXPECT_TRUE(subtract(s.a, s.a).empty());
  EXPECT_TRUE(intersect(subtract(s.a, s.b), s.b).empty());
}

TEST(Csg, ComplementTwiceGivesBackTheSolidInsideTheDomain) {
  Shapes s;
  EXPECT_EQ(complement(complement(s.d, s.domain), s.domain), s.d);
  EXPECT_EQ(complement(s.d, s.domain).voxel_count() + s.d.voxel_count(), s.domain.voxel_count());
}

TEST(Csg, InclusionExclusionOfCounts) {
  Shapes s;
  EXPECT_EQ(unite(s.a, s.b).voxel_count() + intersect(s.a, s.b).voxel_count(), s.a.voxel_count() + s.b.voxel_count());
  EXPECT_GT(intersect(s.a, s.b).voxel_count(), 0);  // the shapes really overlap
  EXPECT_LT(intersect(s.a, s.b).voxel_count(), s.a.voxel_count());
}

TEST(Csg, DisjointSolidsHaveAnEmptyIntersection) {
  const Solid left = make_box(kLattice, {{0, 0, 0}, {10, 10, 10}});
  const Solid right = make_box(kLattice, {{10, 0, 0}, {20, 10, 10}});
  EXPECT_TRUE(intersect(left, right).empty());
  EXPECT_EQ(unite(left, right), make_box(kLattice, {{0, 0, 0}, {20, 10, 10}}));
}

TEST(Csg, SolidsOnDifferentLatticesDoNotCombine) {
  const Solid fine = make_sphere({0.25, {0, 0, 0}}, {0, 0, 0}, 3);
  const Solid shifted = make_sphere({0.5, {0.1, 0, 0}}, {0, 0, 0}, 3);
  const Solid coarse = make_sphere(kLattice, {0, 0, 0}, 3);
  EXPECT_THROW(unite(fine, coarse), std::invalid_argument);
  EXPECT_THROW(intersect(shifted, coarse), std::invalid_argument);
}

TEST(Csg, RigidMotionsCommuteWithBooleanOperations) {
  Shapes s;
  const Index3 offset{13, -7, 2};
  EXPECT_EQ(translate(unite(s.a, s.b), offset), unite(translate(s.a, offset), translate(s.b, offset)));
  EXPECT_EQ(rotate_quarter_turns(subtract(s.b, s.c), Axis::X, 1),
            subtract(rotate_quarter_turns(s.b, Axis::X, 1), rotate_quarter_turns(s.c, Axis::X, 1)));
}

}  // namespace
}  // namespace hybridctl::geometry
