// planner::measure_deviation: the one measure of how far a made solid is from the design
// (plan.json's deviation, dry-run's "vs design" line).

#include "planner/deviation.hpp"

#include <gtest/gtest.h>

namespace hybridctl::planner {
namespace {

using geometry::Solid;

const geometry::Lattice kLattice{1.0, {0, 0, 0}};
const geometry::IndexBox kDomain{{0, 0, 0}, {12, 12, 12}};

TEST(Deviation, TheDesignItselfDeviatesNothing) {
  const Solid design = Solid::filled(kLattice, {{2, 2, 2}, {8, 8, 8}});
  const Deviation d = measure_deviation(design, design, kDomain, 0.0);
  EXPECT_EQ(d.over_volume, 0);
  EXPECT_EQ(d.under_volume, 0);
  EXPECT_EQ(d.worst_distance, 0);
  EXPECT_TRUE(d.within_tolerance);
}

TEST(Deviation, DepthsAreToTheSurfaceBetweenVoxels) {
  const Solid design = Solid::filled(kLattice, {{2, 2, 2}, {8, 8, 8}});
  // Two layers too many at +X, one too few at -X.
  const Solid made = Solid::filled(kLattice, {{3, 2, 2}, {10, 8, 8}});
  const Deviation d = measure_deviation(made, design, kDomain, 1.0);
  EXPECT_EQ(d.over_volume, 72);
  EXPECT_EQ(d.under_volume, 36);
  EXPECT_DOUBLE_EQ(d.worst_over, 1.5);
  EXPECT_DOUBLE_EQ(d.worst_under, 0.5);
  EXPECT_DOUBLE_EQ(d.worst_distance, 1.5);
  EXPECT_FALSE(d.within_tolerance);
  EXPECT_TRUE(measure_deviation(made, design, kDomain, 1.5).within_tolerance);
}

}  // namespace
}  // namespace hybridctl::planner
