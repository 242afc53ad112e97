// A bead's shape as the material simulation lays it, and what follows from it for the
// deposition generator: how wide it is at a height, how deep two tracks meet on top.

#include "instruments/bead.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hybridctl::instruments {
namespace {

Bead bead(config::BeadShape shape) {
  Bead b;
  b.shape = shape;
  b.width = 1.2;
  b.height = 0.5;
  return b;
}

TEST(Bead, AnEllipsoidIsFullWidthUpToItsMiddleAndNarrowsAsTheEllipseAbove) {
  const Bead b = bead(config::BeadShape::Ellipsoid);
  EXPECT_DOUBLE_EQ(bead_half_width_at(b, 0), 0.6);
  EXPECT_DOUBLE_EQ(bead_half_width_at(b, 0.25), 0.6);
  EXPECT_NEAR(bead_half_width_at(b, 0.4), 0.6 * std::sqrt(1 - 0.6 * 0.6), 1e-12);
  EXPECT_DOUBLE_EQ(bead_half_width_at(b, 0.6), 0) << "above the bead";
}

TEST(Bead, TwoEllipsoidTracksMeetUnderTheirCrestsWhereTheirEllipsesCross) {
  // 0.84 mm apart, 1.2 wide: they cross 0.42 off each axis, 0.7 of the half-width out,
  // where the upper half-ellipse of half-height 0.25 stands 0.25 sqrt(1 - 0.49) high.
  const Bead b = bead(config::BeadShape::Ellipsoid);
  EXPECT_NEAR(bead_top_dip(b, 0.84), 0.25 * (1 - std::sqrt(1 - 0.49)), 1e-12);
  EXPECT_DOUBLE_EQ(bead_top_dip(b, 0), 0) << "one on the other";
  EXPECT_DOUBLE_EQ(bead_top_dip(b, 2.0), 0.25) << "tracks that do not meet: down to their middle height";
  EXPECT_DOUBLE_EQ(bead_top_dip(bead(config::BeadShape::Cylinder), 0.84), 0) << "a cylinder's top is flat";
}

}  // namespace
}  // namespace hybridctl::instruments
