// The interval a line meets a swept instrument in: the closed forms (level and plunging
// cylinders, whole spheres and ellipsoids) against a point-by-point check of the
// definition, and the general convex search against the closed forms.
#include "verification/line_sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace hybridctl::verification {
namespace {

using geometry::Vec3;
using Kind = sim::ConvexPiece::Kind;

sim::ConvexPiece cylinder(double r, double from, double to) {
  sim::ConvexPiece p;
  p.kind = Kind::Cylinder, p.radius = r, p.from = from, p.to = to;
  return p;
}
sim::ConvexPiece sphere(double r, double centre) {
  sim::ConvexPiece p;
  p.kind = Kind::Sphere, p.radius = r, p.centre = centre, p.from = centre - r, p.to = centre + r;
  return p;
}

// Whether q lies in the piece placed at some point of the segment: the definition, by
// dense sampling of the segment (the margin covers the sampling's own error).
bool in_sweep(const sim::ConvexPiece& piece, const sim::Segment& s, Vec3 q, double margin) {
  for (int k = 0; k <= 4000; ++k) {
    const double u = k / 4000.0;
    const Vec3 v{q.x - (s.from.x + u * (s.to.x - s.from.x)), q.y - (s.from.y + u * (s.to.y - s.from.y)),
                 q.z - (s.from.z + u * (s.to.z - s.from.z))};
    const double radial = std::hypot(v.x, v.y);
    if (v.z < piece.from - margin || v.z > piece.to + margin) continue;
    double shape = 0;
    switch (piece.kind) {
      case Kind::Cylinder: shape = radial - piece.radius; break;
      case Kind::Sphere: shape = std::hypot(radial, v.z - piece.centre) - piece.radius; break;
      case Kind::Ellipsoid:
        shape = std::hypot(radial, (v.z - piece.centre) * piece.radius / piece.half_height) - piece.radius;
        break;
      case Kind::Torus: shape = std::hypot(std::max(0.0, radial - piece.ring), v.z - piece.centre) - piece.radius; break;
    }
    if (shape <= margin) return true;
  }
  return false;
}

// Checks line_in_sweep on random lines: points well inside its interval are in the sweep,
// points well outside are not.
void check_against_definition(const sim::ConvexPiece& piece, const sim::Segment& segment, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(-6, 6), dir(-1, 1);
  int met = 0;
  for (int n = 0; n < 60; ++n) {
    const Vec3 p{coord(rng), coord(rng), coord(rng)};
    Vec3 d{dir(rng), dir(rng), dir(rng)};
    const double len = std::hypot(d.x, d.y, d.z);
    d = {d.x / len, d.y / len, d.z / len};
    const Span span = line_in_sweep(piece, segment, p, d, -8, 8);
    for (double t = -8; t <= 8; t += 0.05) {
      const Vec3 q{p.x + t * d.x, p.y + t * d.y, p.z + t * d.z};
      const bool inside = !span.empty() && t >= span.lo && t <= span.hi;
      const double edge = span.empty() ? 1e9 : std::min(std::abs(t - span.lo), std::abs(t - span.hi));
      if (edge < 0.02) continue;  // at the boundary either answer is right
      EXPECT_EQ(inside, in_sweep(piece, segment, q, inside ? 0.01 : -0.005))
          << "line " << n << " at t = " << t << " (span " << span.lo << ", " << span.hi << ")";
      met += inside;
    }
  }
  EXPECT_GT(met, 0) << "no random line met the sweep: the check proved nothing";
}

TEST(LineInSweep, AFlatCutterMovedLevelSweepsACapsuleInXyOverItsFlute) {
  check_against_definition(cylinder(1.5, 0, 4), {{-2, -1, 0}, {3, 2, 0}}, 1);
  // Straight down through the middle: from the tip to the flute's top.
  const Span s = line_in_sweep(cylinder(1.5, 0, 4), {{0, 0, 1}, {5, 0, 1}}, {2, 0, -10}, {0, 0, 1}, -100, 100);
  EXPECT_NEAR(s.lo, 11, 1e-12);
  EXPECT_NEAR(s.hi, 15, 1e-12);
  // Straight down just beside the capsule, over its side and over an end: no contact.
  EXPECT_TRUE(line_in_sweep(cylinder(1.5, 0, 4), {{0, 0, 1}, {5, 0, 1}}, {2, 1.51, -10}, {0, 0, 1}, -100, 100).empty());
  EXPECT_TRUE(line_in_sweep(cylinder(1.5, 0, 4), {{0, 0, 1}, {5, 0, 1}}, {6.07, 1.07, -10}, {0, 0, 1}, -100, 100).empty());
  // Along the segment's own line, at the flute's height: from one end disc's far side to the other's.
  const Span along = line_in_sweep(cylinder(1.5, 0, 4), {{0, 0, 1}, {5, 0, 1}}, {-10, 0, 2}, {1, 0, 0}, -100, 100);
  EXPECT_NEAR(along.lo, 8.5, 1e-12);
  EXPECT_NEAR(along.hi, 16.5, 1e-12);
}

TEST(LineInSweep, APlungeSweepsTheCylinderFromTheLowestTipToTheHighestTop) {
  check_against_definition(cylinder(2, 0, 3), {{0.5, 0.5, -2}, {0.5, 0.5, 1}}, 2);
  const Span s = line_in_sweep(cylinder(2, 0, 3), {{0, 0, 5}, {0, 0, -1}}, {-10, 1, 0}, {1, 0, 0}, -100, 100);
  EXPECT_NEAR(s.lo, 10 - std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(s.hi, 10 + std::sqrt(3.0), 1e-12);
}

// A cylinder on a ramp in closed form: random lines, and the lines a surface's vectors
// most often are (straight down, level along the ramp, level across it), on ramps that
// climb, descend, run steep and nearly level, with a shank that never ends.
TEST(LineInSweep, ACylinderOnARampAgreesWithTheDefinition) {
  check_against_definition(cylinder(1.5, 0, 3), {{-3, 0, -1}, {3, 1, 1.5}}, 3);
  check_against_definition(cylinder(2, 0.5, 4), {{2, 2, 2}, {-1, -3, -2}}, 4);
  check_against_definition(cylinder(1, 0, 2), {{0, 0, 0}, {0.3, 0.2, 4}}, 5);
  check_against_definition(cylinder(2.5, 0, 1), {{-4, 1, 0}, {4, 1, 0.01}}, 6);
  check_against_definition(cylinder(1, 3, std::numeric_limits<double>::infinity()), {{-3, 0, -4}, {3, 1, -2}}, 7);
  const sim::Segment ramp{{0, 0, 0}, {10, 0, 2}};  // 10 mm along X, 2 up
  const sim::ConvexPiece flute = cylinder(3, 0, 5);
  // Straight down at x = 5 in the middle: the cylinder passed there with its tip at z = 1
  // (s = 0.5), and from x = 2 (tip at 0.4) to x = 8 (tip at 1.6) it covers x = 5.
  const Span down = line_in_sweep(flute, ramp, {5, 0, 20}, {0, 0, -1}, -100, 100);
  EXPECT_NEAR(down.lo, 20 - (1.6 + 5), 1e-9);
  EXPECT_NEAR(down.hi, 20 - 0.4, 1e-9);
  // Level along X at z = 0.2: the tip is below 0.2 up to s = 0.1 (x = 1), so from x = -3 to 4.
  const Span along = line_in_sweep(flute, ramp, {-10, 0, 0.2}, {1, 0, 0}, -100, 100);
  EXPECT_NEAR(along.lo, 7, 1e-9);
  EXPECT_NEAR(along.hi, 14, 1e-9);
  // Level across at x = 5, z = 6.5: the top (tip + 5) reaches 6.5 from s = 0.75 (x = 7.5),
  // 2.5 mm away, so |y| <= sqrt(9 - 6.25).
  const Span across = line_in_sweep(flute, ramp, {5, -10, 6.5}, {0, 1, 0}, -100, 100);
  EXPECT_NEAR(across.lo, 10 - std::sqrt(2.75), 1e-9);
  EXPECT_NEAR(across.hi, 10 + std::sqrt(2.75), 1e-9);
  EXPECT_TRUE(line_in_sweep(flute, ramp, {10, -10, 7.5}, {0, 1, 0}, -100, 100).empty());  // over the top's 7
}

TEST(LineInSweep, ABallSweepsACapsuleInAnyDirection) {
  check_against_definition(sphere(2, 2), {{-2, 1, -1}, {2, -1, 2}}, 4);
  // Across the ball's path at its centre height: the capsule's width.
  const Span s = line_in_sweep(sphere(2, 2), {{0, 0, 0}, {4, 0, 0}}, {2, -5, 2}, {0, 1, 0}, -100, 100);
  EXPECT_NEAR(s.lo, 3, 1e-12);
  EXPECT_NEAR(s.hi, 7, 1e-12);
}

TEST(LineInSweep, AnEllipsoidBeadSweepsAScaledCapsule) {
  sim::ConvexPiece bead;
  bead.kind = Kind::Ellipsoid, bead.radius = 0.75, bead.half_height = 0.375, bead.centre = 0.375;
  bead.from = 0, bead.to = 0.75;
  check_against_definition(bead, {{-2, 0, 0}, {2, 1, 0.5}}, 5);
}

TEST(LineInSweep, ATorusCornerMovedLevelAgreesWithTheDefinition) {
  sim::ConvexPiece corner;
  corner.kind = Kind::Torus, corner.radius = 1, corner.ring = 4, corner.centre = 1, corner.from = 0, corner.to = 2;
  check_against_definition(corner, {{-1, -1, 0}, {2, 1, 0}}, 6);
  check_against_definition(corner, {{-1, -1, 0}, {2, 1, 1}}, 7);  // on a ramp
}

TEST(LineInSweep, AHalfBallContinuedByItsShankIsCompletedToTheWholeBall) {
  sim::ConvexPiece lower = sphere(3, 3);
  lower.to = 3;  // a ball cutter's tip: the lower half
  const std::vector<sim::ConvexPiece> cutter{lower, cylinder(3, 3, 12)};
  const std::vector<sim::ConvexPiece> done = completed_pieces(cutter);
  EXPECT_DOUBLE_EQ(done[0].to, 6);
  // Without a shank of its reach it stays a half.
  const std::vector<sim::ConvexPiece> alone{lower, cylinder(2, 3, 12)};
  EXPECT_DOUBLE_EQ(completed_pieces(alone)[0].to, 3);
  // The general search on the half ball agrees with the definition too.
  check_against_definition(lower, {{-2, 0, 0}, {2, 1, 1}}, 8);
}

}  // namespace
}  // namespace hybridctl::verification
