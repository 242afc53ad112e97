// Physics in the additive primitives (planner/primitives/support.hpp): what a head builds layer by
// layer without support, on small voxel shapes. The lattice is 1 mm so a voxel is a
// millimetre and a layer is one voxel; the rule is instruments/support_rule.hpp.

#include <gtest/gtest.h>

#include <cmath>

#include "geometry/solid.hpp"
#include "instruments/support_rule.hpp"
#include "planner/primitives/support.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Axis;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Solid;

const geometry::Lattice kMm{1.0, {0, 0, 0}};
const IndexBox kWorld{{-20, -20, -20}, {40, 40, 40}};
const geometry::AxisDirection kUp{Axis::Z, +1};

instruments::SupportRule rule(double max_overhang, double max_bridge = 0) {
  return instruments::support_rule({max_overhang, max_bridge}, kMm.voxel_size);
}

Solid box(Index3 lo, Index3 hi) {
  Solid s(kMm, kWorld);
  for (int z = lo.z; z < hi.z; ++z)
    for (int y = lo.y; y < hi.y; ++y)
      for (int x = lo.x; x < hi.x; ++x) s.set({x, y, z});
  return s;
}

// A slab 3 voxels thick leaning towards +X: layer k starts at floor(k tan(angle)).
Solid leaning_slab(double angle_deg, int layers) {
  Solid s(kMm, kWorld);
  const double t = std::tan(angle_deg * M_PI / 180);
  for (int z = 0; z < layers; ++z) {
    const int x0 = int(std::floor(z * t));
    for (int y = 0; y < 4; ++y)
      for (int x = x0; x < x0 + 3; ++x) s.set({x, y, z});
  }
  return s;
}

// The first layer (from z = 0 up) where `kept` lacks a voxel of `region`; -1 if none.
int first_cut_layer(const Solid& region, const Solid& kept) {
  const Solid cut = geometry::subtract(region, kept);
  return cut.empty() ? -1 : cut.bounding_box().lo.z;
}

TEST(SelfSupporting, AWallLeaningAtTheHeadsAngleIsKept) {
  const Solid wall = leaning_slab(45, 20);
  EXPECT_EQ(self_supporting(wall, kUp, rule(45)), wall);
  // The same wall leaning along the diagonal: the voxel staircase is no reason to cut it.
  // (Its ends are cut square to the wall: an end cut along X would itself lean 55 degrees.)
  Solid diagonal(kMm, kWorld);
  for (int z = 0; z < 12; ++z)
    for (int y = -20; y < 40; ++y)
      for (int x = -20; x < 40; ++x) {
        const double along = (x + 0.5 + y + 0.5) / std::sqrt(2.0) - (z + 0.5);  // 45 degrees
        if (along >= 0 && along < 3 && std::abs(x - y) <= 10) diagonal.set({x, y, z});
      }
  EXPECT_EQ(self_supporting(diagonal, kUp, rule(45)), diagonal);
  // A vertical wall is kept by any head, even one that builds no overhang.
  const Solid vertical = box({0, 0, 0}, {3, 4, 20});
  EXPECT_EQ(self_supporting(vertical, kUp, rule(0)), vertical);
}

TEST(SelfSupporting, ASixtyDegreeOverhangIsCutWhereItLeansOneVoxelBeyondTheCone) {
  // Layer k of the slab starts at floor(1.73 k): 0, 1, 3, 5, ... Its leading edge (the
  // slab's right side, x0 + 2) leans 0, 0, 1, 2 voxels beyond a 45-degree cone from the
  // plate: layer 3 is the first to pass the one voxel of slack the rule allows.
  const Solid slab = leaning_slab(60, 12);
  const Solid kept = self_supporting(slab, kUp, rule(45));
  EXPECT_EQ(first_cut_layer(slab, kept), 3);
  EXPECT_FALSE(kept.contains({7, 0, 3}));
  EXPECT_TRUE(kept.contains({6, 0, 3}));
  // Nothing kept lies beyond the 45-degree cone from the first layer's edge plus one voxel.
  kept.for_each_voxel([](Index3 v) { EXPECT_LE(v.x, 2 + v.z + 1) << v.x << " " << v.z; });
  // A head that builds 60 degrees keeps it all.
  EXPECT_EQ(self_supporting(slab, kUp, rule(60)), slab);
}

TEST(SelfSupporting, ABridgeWithinTheHeadsSpanIsKeptOneBeyondItIsCut) {
  // Two pillars 2 voxels wide, a deck on them at z 5. The cone (no overhang, one voxel of
  // slack) holds one voxel of the deck beyond each pillar; the air between is the bridge.
  auto deck_on_pillars = [](int gap) {
    Solid s = geometry::unite(box({0, 0, 0}, {2, 3, 5}), box({2 + gap, 0, 0}, {4 + gap, 3, 5}));
    return geometry::unite(s, box({0, 0, 5}, {4 + gap, 3, 6}));
  };
  const Solid short_gap = deck_on_pillars(6);  // 4 voxels of air once the cone holds one each side
  EXPECT_EQ(self_supporting(short_gap, kUp, rule(0, 4)), short_gap);
  const Solid long_gap = deck_on_pillars(7);   // 5 voxels of air
  const Solid kept = self_supporting(long_gap, kUp, rule(0, 4));
  EXPECT_FALSE(kept.contains({5, 1, 5}));
  EXPECT_TRUE(kept.contains({2, 1, 5}));
  EXPECT_TRUE(kept.contains({8, 1, 5}));
  EXPECT_EQ(geometry::subtract(long_gap, kept).voxel_count(), 5 * 3);
  // A head that does not bridge keeps neither deck.
  EXPECT_FALSE(self_supporting(short_gap, kUp, rule(0, 0)).contains({5, 1, 5}));
  // What stands on a bridge is supported by it.
  const Solid with_wall = geometry::unite(short_gap, box({4, 0, 6}, {6, 3, 9}));
  EXPECT_EQ(self_supporting(with_wall, kUp, rule(0, 4)), with_wall);
}

TEST(SelfSupporting, ATeeBuildsUpsideDownButNotUpright) {
  // A stem 4 wide and 10 high under a bar 12 wide and 2 high.
  const Solid tee = geometry::unite(box({4, 0, 0}, {8, 4, 10}), box({-2, 0, 10}, {14, 4, 12}));
  const Solid upright = self_supporting(tee, kUp, rule(45));
  // The stem stands; the bar keeps what the 45-degree cone (and its one voxel of slack)
  // holds from the stem's top edge: 2 voxels out in its first layer, 3 in its second.
  EXPECT_EQ(geometry::intersect(upright, box({-20, -20, 0}, {40, 40, 10})), box({4, 0, 0}, {8, 4, 10}));
  EXPECT_EQ(geometry::intersect(upright, box({-20, -20, 10}, {40, 40, 11})), box({2, 0, 10}, {10, 4, 11}));
  EXPECT_EQ(geometry::intersect(upright, box({-20, -20, 11}, {40, 40, 12})), box({1, 0, 11}, {11, 4, 12}));
  // Turned over (built from -Z, the bar on the plate), all of it is self-supporting.
  EXPECT_EQ(self_supporting(tee, {Axis::Z, -1}, rule(45)), tee);
  // Built from the side (+X), the bar's end is the plate and the stem an overhang.
  const Solid sideways = self_supporting(tee, {Axis::X, +1}, rule(45));
  EXPECT_TRUE(sideways.contains({-2, 1, 11}));
  EXPECT_FALSE(sideways.contains({5, 1, 2}));
}

TEST(SelfSupporting, AFloatingBlockFallsAndTheFirstLayerRestsOnThePlate) {
  const Solid base = box({0, 0, 0}, {4, 4, 2});
  const Solid floating = box({10, 0, 4}, {14, 4, 6});
  const Solid both = geometry::unite(base, floating);
  EXPECT_EQ(self_supporting(both, kUp, rule(45)), base);
  // On its own, the block's first layer is on the plate.
  EXPECT_EQ(self_supporting(floating, kUp, rule(45)), floating);
}

}  // namespace
}  // namespace hybridctl::planner
