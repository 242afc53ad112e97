// The voxel solid: storage, single voxels, runs, measures and rigid motions.

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <tuple>

#include "geometry/solid.hpp"

namespace hybridctl::geometry {
namespace {

const Lattice kUnit{1.0, {0, 0, 0}};

using VoxelSet = std::set<std::tuple<int, int, int>>;

VoxelSet voxels_of(const Solid& s) {
  VoxelSet out;
  s.for_each_voxel([&](Index3 v) { out.insert({v.x, v.y, v.z}); });
  return out;
}

Solid random_solid(std::mt19937& rng, IndexBox domain, double density) {
  Solid s(kUnit, domain);
  std::bernoulli_distribution pick(density);
  for (int z = domain.lo.z; z < domain.hi.z; ++z)
    for (int y = domain.lo.y; y < domain.hi.y; ++y)
      for (int x = domain.lo.x; x < domain.hi.x; ++x)
        if (pick(rng)) s.set({x, y, z});
  return s;
}

TEST(Solid, StartsEmptyAndHoldsWhatIsSet) {
  Solid s(kUnit, {{-70, -3, -2}, {70, 4, 5}});
  EXPECT_TRUE(s.empty());
  s.set({-70, -3, -2});
  s.set({69, 3, 4});
  s.set({0, 0, 0});
  EXPECT_EQ(s.voxel_count(), 3);
  EXPECT_TRUE(s.contains({-70, -3, -2}));
  EXPECT_TRUE(s.contains({69, 3, 4}));
  EXPECT_FALSE(s.contains({1, 0, 0}));
  EXPECT_FALSE(s.contains({1000, 0, 0}));  // outside storage is simply empty
  s.set({0, 0, 0}, false);
  EXPECT_EQ(s.voxel_count(), 2);
}

TEST(Solid, RefusesToSetOutsideItsStorage) {
  Solid s(kUnit, {{0, 0, 0}, {10, 10, 10}});
  EXPECT_THROW(s.set({0, 10, 0}), std::out_of_range);
  EXPECT_THROW(s.set_run(0, 0, -5, 3), std::out_of_range);
}

TEST(Solid, RunsSetExactlyTheirVoxelsAcrossWordBoundaries) {
  for (auto [x0, x1] : {std::pair{-130, 130}, {-64, 0}, {63, 65}, {5, 6}, {0, 64}, {-1, 1}}) {
    Solid s(kUnit, {{-200, 0, 0}, {200, 1, 1}});
    s.set_run(0, 0, x0, x1);
    EXPECT_EQ(s.voxel_count(), x1 - x0) << x0 << ".." << x1;
    EXPECT_TRUE(s.contains({x0, 0, 0}));
    EXPECT_TRUE(s.contains({x1 - 1, 0, 0}));
    EXPECT_FALSE(s.contains({x0 - 1, 0, 0}));
    EXPECT_FALSE(s.contains({x1, 0, 0}));
  }
}

TEST(Solid, BoundingBoxIsTight) {
  Solid s(kUnit, {{-100, -100, -100}, {100, 100, 100}});
  EXPECT_TRUE(s.bounding_box().empty());
  s.set({-65, 7, 3});
  s.set({12, -4, 9});
  EXPECT_EQ(s.bounding_box(), (IndexBox{{-65, -4, 3}, {13, 8, 10}}));
}

TEST(Solid, VolumeIsVoxelCountTimesVoxelVolume) {
  const Lattice half{0.5, {1, 2, 3}};
  const Solid s = Solid::filled(half, {{0, 0, 0}, {10, 4, 2}});
  EXPECT_EQ(s.voxel_count(), 80);
  EXPECT_DOUBLE_EQ(s.volume(), 80 * 0.125);
  const Box3 mm = s.bounding_box_mm();
  EXPECT_DOUBLE_EQ(mm.min.x, 1.0);
  EXPECT_DOUBLE_EQ(mm.max.x, 6.0);
  EXPECT_DOUBLE_EQ(mm.max.z, 4.0);
}

TEST(Lattice, CentresWithinABoxAreThoseWhoseCentreLiesInside) {
  const Lattice l{0.5, {0, 0, 0}};
  // Centres at 0.25, 0.75, ...: [0, 2] holds 0.25..1.75, four voxels.
  EXPECT_EQ(l.centers_within({{0, 0, 0}, {2, 2, 2}}), (IndexBox{{0, 0, 0}, {4, 4, 4}}));
  EXPECT_TRUE(l.centers_within({{0.3, 0, 0}, {0.7, 1, 1}}).empty());
}

TEST(Solid, TranslationMovesEveryVoxelByTheOffset) {
  std::mt19937 rng(7);
  const Solid s = random_solid(rng, {{-20, -5, -5}, {90, 5, 5}}, 0.3);
  for (Index3 offset : {Index3{1, 0, 0}, {-1, 2, -3}, {64, 0, 0}, {-129, 1, 1}, {37, -11, 4}}) {
    const Solid moved = translate(s, offset);
    VoxelSet expected;
    for (auto [x, y, z] : voxels_of(s)) expected.insert({x + offset.x, y + offset.y, z + offset.z});
    EXPECT_EQ(voxels_of(moved), expected) << offset.x << "," << offset.y << "," << offset.z;
  }
}

TEST(Solid, TranslationInMillimetresMustBeWholeVoxels) {
  const Solid s = Solid::filled({0.5, {0, 0, 0}}, {{0, 0, 0}, {2, 2, 2}});
  EXPECT_EQ(translate_mm(s, {1.0, -0.5, 0}).bounding_box(), (IndexBox{{2, -1, 0}, {4, 1, 2}}));
  EXPECT_THROW(translate_mm(s, {0.3, 0, 0}), std::invalid_argument);
}

TEST(Solid, QuarterTurnsMapVoxelCentresByTheRotation) {
  // A voxel centred at (0.5, 1.5, 2.5) turned +90 degrees about Z lands at (-1.5, 0.5, 2.5).
  Solid s(kUnit, {{0, 0, 0}, {4, 4, 4}});
  s.set({0, 1, 2});
  EXPECT_TRUE(rotate_quarter_turns(s, Axis::Z, 1).contains({-2, 0, 2}));
  EXPECT_TRUE(rotate_quarter_turns(s, Axis::X, 1).contains({0, -3, 1}));  // (x, -z, y)
  EXPECT_TRUE(rotate_quarter_turns(s, Axis::Y, 1).contains({2, 1, -1}));  // (z, y, -x)
  EXPECT_TRUE(rotate_quarter_turns(s, Axis::Z, -1).contains({1, -1, 2}));
}

TEST(Solid, FourQuarterTurnsAreTheIdentityAndTwoAreAHalfTurn) {
  std::mt19937 rng(11);
  const Solid s = random_solid(rng, {{-9, -3, 0}, {70, 8, 6}}, 0.2);
  for (Axis axis : {Axis::X, Axis::Y, Axis::Z}) {
    Solid turned = s;
    for (int i = 0; i < 4; ++i) turned = rotate_quarter_turns(turned, axis, 1);
    EXPECT_EQ(turned, s);
    EXPECT_EQ(rotate_quarter_turns(s, axis, 2), rotate_quarter_turns(rotate_quarter_turns(s, axis, 1), axis, 1));
    EXPECT_EQ(rotate_quarter_turns(s, axis, 1).voxel_count(), s.voxel_count());
  }
}

TEST(Solid, QuarterTurnsMoveEveryVoxelWhereTheRotationTakesItsCentre) {
  std::mt19937 rng(5);
  const Solid s = random_solid(rng, {{-70, -5, -2}, {9, 7, 66}}, 0.15);
  for (Axis axis : {Axis::X, Axis::Y, Axis::Z})
    for (int turns = 1; turns <= 3; ++turns) {
      VoxelSet expected;
      for (const auto& [x, y, z] : voxels_of(s)) {
        Index3 v{x, y, z};
        for (int t = 0; t < turns; ++t)  // a right-handed quarter turn of the centre (v + 0.5)
          v = axis == Axis::X ? Index3{v.x, -v.z - 1, v.y} : axis == Axis::Y ? Index3{v.z, v.y, -v.x - 1} : Index3{-v.y - 1, v.x, v.z};
        expected.insert({v.x, v.y, v.z});
      }
      EXPECT_EQ(voxels_of(rotate_quarter_turns(s, axis, turns)), expected) << int(axis) << " " << turns;
    }
}

}  // namespace
}  // namespace hybridctl::geometry
