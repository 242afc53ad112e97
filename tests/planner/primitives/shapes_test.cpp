// Primitive shapes: openings and closings when the instrument has no body, and
// accessibility (the shank's shadow) when it has one.

#include <gtest/gtest.h>

#include "geometry/shapes.hpp"
#include "planner/primitives/shapes.hpp"

namespace hybridctl::planner {
namespace {

using namespace hybridctl::geometry;

const Lattice kLattice{0.5, {0, 0, 0}};

// A mushroom: a 4 x 4 column under a 10 x 10 cap.
Solid mushroom() {
  return unite(make_box(kLattice, {{3, 3, 0}, {7, 7, 6}}), make_box(kLattice, {{0, 0, 6}, {10, 10, 8}}));
}

TEST(PrimitiveShapes, WithoutABodyUamIsTheOpeningAndSmMaxTheComplementOfTheClosing) {
  const Solid s = unite(make_box(kLattice, {{0, 0, 0}, {8, 3, 3}}), make_box(kLattice, {{0, 0, 0}, {3, 8, 3}}));
  const Instrument bead{{Ball{1.0}}, {}};
  EXPECT_EQ(additive_maximal(s, bead), open(s, Ball{1.0}));
  const IndexBox domain{{-10, -10, -10}, {30, 30, 20}};
  EXPECT_EQ(subtractive_maximal(s, bead, domain), complement(close(s, Ball{1.0}), domain));
  EXPECT_EQ(additive_conservative(s, bead), dilate(s, Ball{1.0}));
  EXPECT_EQ(subtractive_conservative(s, bead, domain), complement(erode(s, Ball{1.0}), domain));
  // U-AM never deposits outside the design; SM-max never cuts into it.
  EXPECT_TRUE(subtract(additive_maximal(s, bead), s).empty());
  EXPECT_TRUE(intersect(subtractive_maximal(s, bead, domain), s).empty());
}

TEST(PrimitiveShapes, AShankFromAboveCannotReachUnderTheCap) {
  const Solid s = mushroom();
  const IndexBox domain{{-6, -6, -2}, {26, 26, 22}};
  AxialBody cutter = cylinder_body({Axis::Z, +1}, 1.0, 2.0);
  AxialBody shank{{Axis::Z, +1}, {{AxialSection::Kind::Cylinder, 2.0, std::numeric_limits<double>::infinity(), 1.0, 0, 0}}};
  const Instrument mill{{cutter}, {shank}};
  const Solid removable = subtractive_maximal(s, mill, domain);
  EXPECT_TRUE(intersect(removable, s).empty());
  // Under the cap, beside the column: unreachable from +Z.
  EXPECT_FALSE(removable.contains({2, 2, 4}));   // (1.25, 1.25, 2.25) mm
  // Above the cap and well beside it: reachable.
  EXPECT_TRUE(removable.contains({10, 10, 18}));  // (5.25, 5.25, 9.25) mm
  EXPECT_TRUE(removable.contains({-4, 10, 4}));   // (-1.75, 5.25, 2.25) mm
  // Without the shank the same cutter would reach some of it from below the cap's rim.
  const Solid from_below = subtractive_maximal(s, Instrument{{cylinder_body({Axis::Z, -1}, 1.0, 2.0)}, {}}, domain);
  EXPECT_TRUE(from_below.contains({2, 2, 4}));
}

}  // namespace
}  // namespace hybridctl::planner
