// Moves become straight segments: lines as they are, arcs as chords within the chord
// tolerance of the true arc, turning the programmed way, ending exactly at the end point.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim/moves.hpp"

namespace hybridctl::sim {
namespace {

double angle_of(Vec3 p, Vec3 c) { return std::atan2(p.y - c.y, p.x - c.x); }

TEST(PathSegments, LinesAndRapidsAreOneSegment) {
  for (Motion m : {Motion::Rapid, Motion::Linear}) {
    const auto s = path_segments({m, {1, 2, 3}, {4, 5, 6}, {}, false, 1}, 0.01);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].from, (Vec3{1, 2, 3}));
    EXPECT_EQ(s[0].to, (Vec3{4, 5, 6}));
  }
  EXPECT_THROW(path_segments({Motion::Linear, {}, {1, 0, 0}, {}, false, 1}, 0), std::invalid_argument);
}

TEST(PathSegments, ArcChordsStayWithinTheToleranceAndTurnTheProgrammedWay) {
  const Vec3 c{10, 5, 0};
  const double r = 7, tol = 0.01;
  // A quarter turn from angle 0 to 90 degrees, counter-clockwise and the long way round.
  const Vec3 from{c.x + r, c.y, 2}, to{c.x, c.y + r, 4};
  for (Motion m : {Motion::ArcCcw, Motion::ArcCw}) {
    const auto segs = path_segments({m, from, to, c, false, 3}, tol);
    const double sweep = m == Motion::ArcCcw ? std::numbers::pi / 2 : -3 * std::numbers::pi / 2;
    // Few chords: no more than twice what the sagitta bound needs.
    const double needed = std::abs(sweep) / (2 * std::acos(1 - tol / r));
    EXPECT_LE(double(segs.size()), 2 * needed + 1);
    EXPECT_GE(double(segs.size()), needed);
    EXPECT_EQ(segs.front().from, from);
    EXPECT_EQ(segs.back().to, to);
    double turned = 0;
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const Segment& s = segs[i];
      if (i > 0) {
        EXPECT_EQ(s.from, segs[i - 1].to);
      }
      EXPECT_NEAR(std::hypot(s.to.x - c.x, s.to.y - c.y), r, 1e-9);  // vertices on the arc
      const Vec3 mid{(s.from.x + s.to.x) / 2, (s.from.y + s.to.y) / 2, 0};
      EXPECT_LE(r - std::hypot(mid.x - c.x, mid.y - c.y), tol + 1e-12);  // sagitta
      double step = angle_of(s.to, c) - angle_of(s.from, c);
      if (step > std::numbers::pi) step -= 2 * std::numbers::pi;
      if (step < -std::numbers::pi) step += 2 * std::numbers::pi;
      EXPECT_EQ(step > 0, m == Motion::ArcCcw);
      turned += step;
      // Helix: z moves in proportion to the angle.
      EXPECT_NEAR(s.to.z, 2 + 2 * (turned / sweep), 1e-9);
    }
    EXPECT_NEAR(turned, sweep, 1e-9);
  }
}

TEST(PathSegments, AnArcEndingWhereItStartsIsAFullTurn) {
  const Vec3 c{0, 0, 0}, p{5, 0, 1};
  for (Motion m : {Motion::ArcCcw, Motion::ArcCw}) {
    const auto segs = path_segments({m, p, p, c, false, 1}, 0.005);
    double turned = 0;
    for (const Segment& s : segs) {
      double step = angle_of(s.to, c) - angle_of(s.from, c);
      if (step > std::numbers::pi) step -= 2 * std::numbers::pi;
      if (step < -std::numbers::pi) step += 2 * std::numbers::pi;
      turned += step;
    }
    EXPECT_NEAR(std::abs(turned), 2 * std::numbers::pi, 1e-9);
    EXPECT_GT(segs.size(), 20u);
  }
}

}  // namespace
}  // namespace hybridctl::sim
