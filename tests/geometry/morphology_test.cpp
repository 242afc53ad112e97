// Morphology is exact: every fast path equals, voxel for voxel, the brute-force
// Minkowski sum of the same discrete element, and so does the FFT convolution.

#include <gtest/gtest.h>

#include <random>

#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"

namespace hybridctl::geometry {
namespace {

const Lattice kLattice{0.5, {0, 0, 0}};

// A lumpy test solid: a box with a notch, a sphere and scattered single voxels, so
// that corners, thin parts and isolated points all appear.
Solid lumpy(std::uint32_t seed) {
  Solid s = unite(subtract(make_box(kLattice, {{0, 0, 0}, {6, 5, 4}}), make_box(kLattice, {{2, 1, 2}, {4, 5, 4}})),
                  make_sphere(kLattice, {7, 3, 2}, 1.6));
  std::mt19937 rng(seed);
  Solid scattered(kLattice, {{-4, -4, -4}, {20, 14, 12}});
  for (int i = 0; i < 12; ++i) scattered.set({int(rng() % 24) - 4, int(rng() % 18) - 4, int(rng() % 16) - 4});
  return unite(s, scattered);
}

AxialBody flat_mill_with_shank_and_holder(AxisDirection dir) {
  return {dir,
          {{AxialSection::Kind::Cylinder, 0, 2.0, 1.0, 0, 0},
           {AxialSection::Kind::Cylinder, 2.0, 3.0, 0.6, 0, 0},
           {AxialSection::Kind::Cylinder, 3.0, 4.0, 1.8, 0, 0}}};
}

AxialBody ball_end_mill(AxisDirection dir) {
  return {dir,
          {{AxialSection::Kind::Sphere, 0, 1.5, 1.5, 1.5, 0}, {AxialSection::Kind::Cylinder, 1.5, 3.5, 1.5, 0, 0}}};
}

AxialBody bull_nose_mill(AxisDirection dir) {
  return {dir,
          {{AxialSection::Kind::Torus, 0, 0.75, 0.75, 0.75, 1.0}, {AxialSection::Kind::Cylinder, 0.75, 3.0, 1.75, 0, 0}}};
}

struct Case {
  const char* name;
  StructuringElement element;
};

std::vector<Case> finite_cases() {
  std::vector<Case> cases = {
      {"ball r=1.3mm", Ball{1.3}},
      {"ball r=2mm", Ball{2.0}},
      {"ellipsoid bead", Ellipsoid{{1.6, 1.1, 0.7}}},
      {"flat mill +Z", flat_mill_with_shank_and_holder({Axis::Z, +1})},
      {"flat mill -Z", flat_mill_with_shank_and_holder({Axis::Z, -1})},
      {"flat mill +X", flat_mill_with_shank_and_holder({Axis::X, +1})},
      {"flat mill -Y", flat_mill_with_shank_and_holder({Axis::Y, -1})},
      {"ball-end mill +Z", ball_end_mill({Axis::Z, +1})},
      {"ball-end mill -X (whole-ball tip path, other way)", ball_end_mill({Axis::X, -1})},
      {"bull-nose mill -X", bull_nose_mill({Axis::X, -1})},
      {"cylinder bead", cylinder_body({Axis::Z, +1}, 1.2, 0.5)},
      {"odd voxel set", VoxelOffsets{{{0, 0, 0}, {3, -1, 0}, {-2, 2, 1}, {0, 0, -3}}}},
  };
  return cases;
}

TEST(Morphology, FastDilationEqualsTheBruteForceMinkowskiSum) {
  for (const Case& c : finite_cases()) {
    for (std::uint32_t seed : {1u, 2u}) {
      const Solid s = lumpy(seed);
      const Solid fast = dilate(s, c.element);
      const Solid brute = dilate(s, c.element, {}, MorphologyMethod::BruteForce);
      EXPECT_GT(brute.voxel_count(), s.voxel_count()) << c.name;
      EXPECT_EQ(fast, brute) << c.name << " seed " << seed;
    }
  }
}

TEST(Morphology, EveryExactMethodEqualsTheBruteForceMinkowskiSum) {
  for (const Case& c : finite_cases()) {
    const Solid s = lumpy(4);
    const Solid brute = dilate(s, c.element, {}, MorphologyMethod::BruteForce);
    EXPECT_EQ(dilate(s, c.element, {}, MorphologyMethod::Shifts), brute) << c.name;
    if (!std::holds_alternative<VoxelOffsets>(c.element)) {
      EXPECT_EQ(dilate(s, c.element, {}, MorphologyMethod::DistanceTransform), brute) << c.name;
    }
  }
  // Shifts across word boundaries in both directions, into a domain that clips them.
  Solid row(kLattice, {{-130, 0, 0}, {130, 1, 1}});
  for (int x : {-129, -64, -63, -1, 0, 63, 64, 127}) row.set({x, 0, 0});
  const StructuringElement far = VoxelOffsets{{{-70, 0, 0}, {65, 0, 0}, {1, 0, 0}, {-1, 0, 0}}};
  const IndexBox clip{{-150, 0, 0}, {100, 1, 1}};
  EXPECT_EQ(dilate(row, far, clip, MorphologyMethod::Shifts), dilate(row, far, clip, MorphologyMethod::BruteForce));
}

TEST(Morphology, FftConvolutionEqualsTheBruteForceMinkowskiSum) {
  for (const Case& c : finite_cases()) {
    const Solid s = lumpy(3);
    EXPECT_EQ(dilate(s, c.element, {}, MorphologyMethod::Fft), dilate(s, c.element, {}, MorphologyMethod::BruteForce))
        << c.name;
  }
}

TEST(Morphology, DilationByABallIsEveryVoxelWithinTheRadiusOfTheSolid) {
  Solid point(kLattice, {{0, 0, 0}, {1, 1, 1}});
  point.set({0, 0, 0});
  // r = 1 mm = 2 voxels: offsets with |d|^2 <= 4: 1 + 6 + 12 + 8 + 6 = 33 voxels.
  EXPECT_EQ(dilate(point, Ball{1.0}).voxel_count(), 33);
}

TEST(Morphology, TheShadowOfAnInfiniteShankReachesTheDomainBoundary) {
  Solid s(kLattice, {{0, 0, 0}, {10, 10, 10}});
  s.set({4, 4, 3});
  s.set({6, 2, 7});
  const IndexBox domain{{0, 0, 0}, {10, 10, 10}};
  const Solid shadow = dilate(s, ray_body({Axis::Z, -1}), domain);
  EXPECT_EQ(shadow.voxel_count(), 4 + 8);  // z = 0..3 and z = 0..7
  EXPECT_TRUE(shadow.contains({4, 4, 0}));
  EXPECT_FALSE(shadow.contains({4, 4, 4}));
  EXPECT_EQ(shadow, dilate(s, ray_body({Axis::Z, -1}), domain, MorphologyMethod::BruteForce));
  // A mill with a shank that never ends: exact too.
  AxialBody endless = flat_mill_with_shank_and_holder({Axis::Z, +1});
  endless.sections.back().to = std::numeric_limits<double>::infinity();
  const Solid part = lumpy(4);
  const IndexBox big{{-10, -10, -10}, {25, 20, 30}};
  EXPECT_EQ(dilate(part, endless, big), dilate(part, endless, big, MorphologyMethod::BruteForce));
  EXPECT_THROW(dilate(part, endless), std::invalid_argument);
}

TEST(Morphology, ErosionIsWhereTheWholeElementFitsInside) {
  const Solid s = unite(make_box(kLattice, {{0, 0, 0}, {8, 6, 5}}), make_sphere(kLattice, {9, 3, 2.5}, 2.5));
  for (const Case& c : finite_cases()) {
    const Solid eroded = erode(s, c.element);
    // Definition: p survives iff p + d is in s for every offset d.
    const auto offsets = offsets_of(c.element, kLattice.voxel_size);
    Solid expected(kLattice, s.bounding_box());
    const IndexBox b = s.bounding_box();
    for (int z = b.lo.z; z < b.hi.z; ++z)
      for (int y = b.lo.y; y < b.hi.y; ++y)
        for (int x = b.lo.x; x < b.hi.x; ++x) {
          bool fits = true;
          for (const Index3& d : offsets) fits = fits && s.contains({x + d.x, y + d.y, z + d.z});
          if (fits) expected.set({x, y, z});
        }
    EXPECT_EQ(eroded, expected) << c.name;
  }
}

TEST(Morphology, ErosionByAnInfiniteElementLeavesNothingOfABoundedSolid) {
  const Solid s = make_box(kLattice, {{0, 0, 0}, {4, 4, 4}});
  EXPECT_TRUE(erode(s, ray_body({Axis::Z, +1})).empty());
}

TEST(Morphology, OpeningIsInsideAndClosingContainsTheSolid) {
  const Solid s = lumpy(5);
  for (const StructuringElement& e : {StructuringElement{Ball{1.0}}, StructuringElement{ball_end_mill({Axis::Z, -1})}}) {
    const Solid opened = open(s, e), closed = close(s, e);
    EXPECT_TRUE(subtract(opened, s).empty());
    EXPECT_TRUE(subtract(s, closed).empty());
    EXPECT_LT(opened.voxel_count(), s.voxel_count());  // the scattered voxels go
    EXPECT_EQ(open(opened, e), opened);                // idempotent
  }
}

TEST(Morphology, ReflectionMirrorsTheOffsets) {
  const auto up = offsets_of(flat_mill_with_shank_and_holder({Axis::Y, +1}), 0.5);
  const auto down = offsets_of(reflected(flat_mill_with_shank_and_holder({Axis::Y, +1})), 0.5);
  ASSERT_EQ(up.size(), down.size());
  for (const Index3& d : up) EXPECT_NE(std::find(down.begin(), down.end(), Index3{-d.x, -d.y, -d.z}), down.end());
}

}  // namespace
}  // namespace hybridctl::geometry
