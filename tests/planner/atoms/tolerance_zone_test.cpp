// planner::make_tolerance_zone: the core and hull, and the parts of the design and its
// air they do not cover within the tolerance: `thin` (fins, thin walls, sharp convex
// edges: what an opening removes) and `narrow` (slots, gaps, sharp concave edges: what a
// closing fills). One and two voxels across.

#include "planner/atoms/tolerance_zone.hpp"

#include <gtest/gtest.h>

#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"
#include "plan/deviation.hpp"

namespace hybridctl::planner {
namespace {

using geometry::IndexBox;
using geometry::Lattice;
using geometry::make_box;
using geometry::Solid;
using geometry::Vec3;

const Lattice kUnit{1.0, {0, 0, 0}};
const IndexBox kDomain{{0, 0, 0}, {32, 32, 28}};

Solid box(Vec3 lo, Vec3 hi) { return make_box(kUnit, {lo, hi}); }

// A plate 3 thick and a fin `thickness` voxels thick and 12 tall on it.
Solid plate() { return box({4, 4, 2}, {28, 28, 5}); }
Solid fin(int thickness) { return box({14, 6, 5}, {14.0 + thickness, 26, 17}); }

TEST(ToleranceZone, AThinFinHasNoCoreAndIsThin) {
  for (int thickness : {1, 2}) {
    const Solid design = unite(plate(), fin(thickness));
    const ToleranceZone z = make_tolerance_zone(design, 1.0);
    EXPECT_TRUE(intersect(z.core, fin(thickness)).empty());
    // All of the fin but its foot, which the plate's core covers.
    EXPECT_TRUE(subtract(fin(thickness), unite(z.thin, box({14, 6, 5}, {16, 26, 6}))).empty()) << thickness;
    EXPECT_TRUE(subtract(z.thin, design).empty());
    // The core and hull alone let a plan make the plate without the fin: 12 voxels off.
    EXPECT_TRUE(subtract(z.core, plate()).empty());
    EXPECT_DOUBLE_EQ(plan::measure_deviation(plate(), design, kDomain, 1.0).worst_missing, 12.0);
  }
}

TEST(ToleranceZone, ANarrowSlotLiesInTheHullAndIsNarrow) {
  for (int width : {1, 2}) {
    const Solid block = box({4, 4, 2}, {28, 28, 14}), slot = box({14, 4, 5}, {14.0 + width, 28, 14});
    const ToleranceZone z = make_tolerance_zone(subtract(block, slot), 1.0);
    EXPECT_TRUE(subtract(slot, z.hull).empty());
    // All of the slot but its mouth and ends, which the air beyond the hull covers.
    EXPECT_TRUE(subtract(box({14, 5, 5}, {14.0 + width, 27, 13}), z.narrow).empty()) << width;
    EXPECT_TRUE(subtract(z.narrow, slot).empty());
  }
}

// With a tolerance of one voxel a cube's whole outer layer is in the band, but a cube
// shaved by it is sqrt(3) voxels off at its corners: edges and corners are thin, faces not.
TEST(ToleranceZone, SharpEdgesAreThinWhenShavingTheBandWouldRoundThem) {
  const Solid design = box({8, 8, 8}, {20, 20, 20});
  const ToleranceZone z = make_tolerance_zone(design, 1.0);
  EXPECT_TRUE(z.thin.contains({8, 8, 8}));
  EXPECT_TRUE(z.thin.contains({8, 8, 14}));
  EXPECT_FALSE(z.thin.contains({8, 14, 14}));
  EXPECT_TRUE(z.narrow.empty());  // a box has no concave edge
}

TEST(ToleranceZone, AToleranceBelowAVoxelOrZeroIsTheDesignItself) {
  const Solid design = unite(plate(), fin(1));
  for (double t : {0.0, 0.5}) {
    const ToleranceZone z = make_tolerance_zone(design, t);
    EXPECT_EQ(z.core, design);
    EXPECT_EQ(z.hull, design);
    EXPECT_TRUE(z.thin.empty());
    EXPECT_TRUE(z.narrow.empty());
  }
}

}  // namespace
}  // namespace hybridctl::planner
