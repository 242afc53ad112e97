// geometry::DistanceField and farthest_voxel: distances between voxel centres, kept as
// values, from the same transform the morphology uses.

#include "geometry/distance_field.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"

namespace hybridctl::geometry {
namespace {

const Lattice kHalf{0.5, {0, 0, 0}};

TEST(DistanceField, HoldsSquaredVoxelDistancesToTheNearestVoxel) {
  Solid point(kHalf, {{0, 0, 0}, {10, 10, 10}});
  point.set({5, 5, 5});
  const DistanceField field(point, {{0, 0, 0}, {10, 10, 10}});
  EXPECT_EQ(field.squared({5, 5, 5}), 0.0f);
  EXPECT_EQ(field.squared({8, 5, 5}), 9.0f);
  EXPECT_EQ(field.squared({6, 7, 3}), 1.0f + 4.0f + 4.0f);
  EXPECT_DOUBLE_EQ(field.distance_mm({8, 9, 5}), 2.5);  // (3, 4) voxels of 0.5 mm
}

TEST(DistanceField, IsInfiniteWhereNothingIsInTheBox) {
  Solid far(kHalf, {{20, 20, 20}, {21, 21, 21}});
  far.set({20, 20, 20});
  const DistanceField field(far, {{0, 0, 0}, {4, 4, 4}});
  EXPECT_TRUE(std::isinf(field.squared({1, 1, 1})));
}

TEST(FarthestVoxel, NamesTheVoxelAndAgreesWithFarthestDistance) {
  const Solid block = make_box(kHalf, {{0, 0, 0}, {10, 10, 10}});
  Solid from(kHalf, {{0, 0, 0}, {60, 30, 30}});
  from.set({22, 10, 10});  // 3 voxels from the block's last voxel (x = 19)
  from.set({49, 5, 5});    // 30 voxels beyond it: farthest
  const FarthestVoxel f = farthest_voxel(from, block);
  ASSERT_TRUE(f.voxel.has_value());
  EXPECT_EQ(*f.voxel, (Index3{49, 5, 5}));
  EXPECT_DOUBLE_EQ(f.distance, 15.0);
  EXPECT_DOUBLE_EQ(f.distance, farthest_distance(from, block));
}

TEST(FarthestVoxel, OfNothingIsZeroAndToNothingInfinite) {
  const Solid block = make_box(kHalf, {{0, 0, 0}, {2, 2, 2}});
  const Solid none(kHalf, {});
  EXPECT_EQ(farthest_voxel(none, block).distance, 0);
  EXPECT_FALSE(farthest_voxel(none, block).voxel.has_value());
  const FarthestVoxel f = farthest_voxel(block, none);
  EXPECT_TRUE(std::isinf(f.distance));
  EXPECT_EQ(*f.voxel, (Index3{0, 0, 0}));
}

}  // namespace
}  // namespace hybridctl::geometry
