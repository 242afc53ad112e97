// plan::measure_deviation: the one measure of how far a made solid is from the design,
// both ways (plan.json's deviation, dry-run's "on voxels" line). Known distances on
// simple voxel shapes, and the half-voxel convention.

#include "plan/deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/shapes.hpp"

namespace hybridctl::plan {
namespace {

using geometry::make_box;
using geometry::Solid;
using geometry::Vec3;

const geometry::Lattice kLattice{1.0, {0, 0, 0}};
const geometry::IndexBox kDomain{{0, 0, 0}, {24, 24, 24}};

Solid box(Vec3 lo, Vec3 hi) { return make_box(kLattice, {lo, hi}); }

TEST(Deviation, TheDesignItselfDeviatesNothing) {
  const Solid design = box({2, 2, 2}, {8, 8, 8});
  const Deviation d = measure_deviation(design, design, kDomain, 0.0);
  EXPECT_EQ(d.over_volume, 0);
  EXPECT_EQ(d.under_volume, 0);
  EXPECT_EQ(d.worst_distance, 0);
  EXPECT_EQ(d.worst_out, 0);
  EXPECT_EQ(d.worst_missing, 0);
  EXPECT_FALSE(d.worst_out_at.has_value());
  EXPECT_FALSE(d.worst_missing_at.has_value());
  EXPECT_TRUE(d.within_tolerance);
}

// The half-voxel convention: a voxel is the cube around its centre. One layer too many
// puts the made surface one voxel from the design's (worst_out = h), while the wrong
// voxel's centre lies half a voxel out (worst_over = h/2, the older field).
TEST(Deviation, OneLayerTooManyIsOneVoxelOffBothWays) {
  const Solid design = box({2, 2, 2}, {8, 8, 8});
  const Solid made = box({2, 2, 2}, {9, 8, 8});
  const Deviation d = measure_deviation(made, design, kDomain, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_over, 0.5);
  EXPECT_DOUBLE_EQ(d.worst_out, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_missing, 1.0);
  EXPECT_TRUE(d.within_tolerance);
  EXPECT_FALSE(measure_deviation(made, design, kDomain, 0.5).within_tolerance);
}

TEST(Deviation, DepthsAreToTheSurfaceBetweenVoxels) {
  const Solid design = box({2, 2, 2}, {8, 8, 8});
  // Two layers too many at +X, one too few at -X.
  const Solid made = box({3, 2, 2}, {10, 8, 8});
  const Deviation d = measure_deviation(made, design, kDomain, 1.0);
  EXPECT_EQ(d.over_volume, 72);
  EXPECT_EQ(d.under_volume, 36);
  EXPECT_DOUBLE_EQ(d.worst_over, 1.5);
  EXPECT_DOUBLE_EQ(d.worst_under, 0.5);
  EXPECT_DOUBLE_EQ(d.worst_distance, 1.5);
  EXPECT_DOUBLE_EQ(d.worst_out, 2.0);
  EXPECT_DOUBLE_EQ(d.worst_missing, 2.0);
  // Where: the centre of a voxel of the outer layer at x = 9..10.
  ASSERT_TRUE(d.worst_out_at.has_value());
  EXPECT_DOUBLE_EQ(d.worst_out_at->x, 9.5);
  EXPECT_FALSE(d.within_tolerance);
  EXPECT_TRUE(measure_deviation(made, design, kDomain, 2.0).within_tolerance);
}

// A plate with a 1 voxel thin fin 10 tall: without the fin every wrong voxel is one voxel
// from the design's surface, but the fin's tip is 10 from the plate that was made.
TEST(Deviation, AMissingFinIsReportedByWorstMissingAtItsTip) {
  const Solid plate = box({2, 2, 2}, {20, 20, 5});
  const Solid design = unite(plate, box({10, 4, 5}, {11, 18, 15}));
  const Deviation d = measure_deviation(plate, design, kDomain, 1.0);
  EXPECT_EQ(d.under_volume, 140);
  EXPECT_DOUBLE_EQ(d.worst_out, 1.0);      // each fin voxel is beside the air
  EXPECT_DOUBLE_EQ(d.worst_distance, 0.5);  // the one-sided measure saw nothing wrong
  EXPECT_DOUBLE_EQ(d.worst_missing, 10.0);  // the tip's top face to the plate's
  ASSERT_TRUE(d.worst_missing_at.has_value());
  EXPECT_DOUBLE_EQ(d.worst_missing_at->x, 10.5);
  EXPECT_DOUBLE_EQ(d.worst_missing_at->z, 14.5);
  EXPECT_FALSE(d.within_tolerance);
}

// A block with a slot 1 wide and 4 deep, filled: the slot's floor is 4 from the made top.
TEST(Deviation, AFilledSlotIsReportedByWorstMissingAtItsFloor) {
  const Solid block = box({2, 2, 2}, {20, 20, 14});
  const Solid design = subtract(block, box({10, 2, 10}, {11, 20, 14}));
  const Deviation d = measure_deviation(block, design, kDomain, 1.0);
  EXPECT_EQ(d.over_volume, 72);
  EXPECT_DOUBLE_EQ(d.worst_out, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_missing, 4.0);
  ASSERT_TRUE(d.worst_missing_at.has_value());
  EXPECT_DOUBLE_EQ(d.worst_missing_at->z, 10.5);
  EXPECT_FALSE(d.within_tolerance);
}

// A cube shaved by one layer all round: its faces are one voxel in, its corners sqrt(3)
// voxels (the design's corner to the corner made), its edges sqrt(2).
TEST(Deviation, AShavedCubesCornersAreFartherThanItsFaces) {
  const Solid design = box({4, 4, 4}, {12, 12, 12});
  const Solid made = box({5, 5, 5}, {11, 11, 11});
  const Deviation d = measure_deviation(made, design, kDomain, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_out, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_missing, std::sqrt(3.0));
  ASSERT_TRUE(d.worst_missing_at.has_value());
  EXPECT_DOUBLE_EQ(d.worst_missing_at->x, 4.5);  // the first corner voxel in z, y, x order
  EXPECT_DOUBLE_EQ(d.worst_missing_at->y, 4.5);
  EXPECT_DOUBLE_EQ(d.worst_missing_at->z, 4.5);
  // Still one layer, whatever the direction: within a tolerance of one voxel.
  EXPECT_TRUE(d.within_tolerance);
  EXPECT_FALSE(measure_deviation(made, design, kDomain, 0.9).within_tolerance);
}

// Where a tolerance of a voxel holds one layer too many along an axis, it holds that layer
// round an edge too: the voxel beside the design's edge touches the design at an edge only,
// its centre sqrt(2) voxels from the design's, and is the same one layer the grid
// resolves. A second layer is beyond it.
TEST(Deviation, OneLayerRoundAnEdgeIsOneLayerToo) {
  const Solid design = box({4, 4, 2}, {10, 10, 8});
  const Solid one_layer = box({4, 4, 2}, {11, 11, 8});
  const Deviation d = measure_deviation(one_layer, design, kDomain, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_out, std::sqrt(2.0));  // the column of voxels at (10, 10)
  EXPECT_TRUE(d.within_tolerance);
  const Solid two_layers = box({4, 4, 2}, {12, 12, 8});
  EXPECT_FALSE(measure_deviation(two_layers, design, kDomain, 1.0).within_tolerance);
  EXPECT_GT(measure_deviation(two_layers, design, kDomain, 1.0).worst_out, std::sqrt(3.0));
}

// A hollow box with walls 1 thick, made solid. The surfaces alone are only the wall's
// thickness apart (the cavity's wall from the made outer surface), which a Hausdorff
// distance of surfaces would accept; the measure counts wrong material by its depth.
TEST(Deviation, AFilledCavityIsOutHoweverThinItsWalls) {
  const Solid made = box({2, 2, 2}, {16, 16, 16});
  const Solid design = subtract(made, box({3, 3, 3}, {15, 15, 15}));
  const Deviation d = measure_deviation(made, design, kDomain, 1.0);
  EXPECT_DOUBLE_EQ(d.worst_out, 6.0);      // the cavity's centre voxels from its walls
  EXPECT_DOUBLE_EQ(d.worst_missing, 7.0);  // and from the air around the block made
  EXPECT_FALSE(d.within_tolerance);
}

TEST(Deviation, NothingMadeMissesEverything) {
  const Solid design = box({2, 2, 2}, {8, 8, 8});
  const Deviation d = measure_deviation(Solid(kLattice, kDomain), design, kDomain, 100.0);
  EXPECT_TRUE(std::isinf(d.worst_missing));
  EXPECT_FALSE(d.within_tolerance);
  EXPECT_NE(deviation_text(d, 100.0).find("nothing made"), std::string::npos);
}

TEST(Deviation, TextSaysWithinOnlyWhenBothDirectionsHold) {
  const Solid plate = box({2, 2, 2}, {20, 20, 5});
  const Solid design = unite(plate, box({10, 4, 5}, {11, 18, 15}));
  const std::string missing_fin = deviation_text(measure_deviation(plate, design, kDomain, 1.0), 1.0);
  EXPECT_NE(missing_fin.find("OUTSIDE the planning band (1 mm)"), std::string::npos) << missing_fin;
  EXPECT_NE(missing_fin.find("missing 10.00 mm at (10.50, "), std::string::npos) << missing_fin;
  EXPECT_EQ(missing_fin.find("within"), std::string::npos) << missing_fin;
  const std::string exact = deviation_text(measure_deviation(design, design, kDomain, 1.0), 1.0);
  EXPECT_NE(exact.find("within the planning band (1 mm)"), std::string::npos) << exact;
}

}  // namespace
}  // namespace hybridctl::plan
