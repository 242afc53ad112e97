// Wall finishing's keep-out region against closed forms: for a flat end mill at a tip
// height, the loops of toolpaths::tip_keep_out are where its side touches the design's
// walls. Each case builds a closed mesh, takes the loops and measures them against the
// exact polygons the STL makes (a 48-gon is not a circle: compare with the polygon):
//   - every point of a loop (its vertices and points along its chords) stands off the
//     limiting wall by the band's radius plus [clearance, clearance + chord tolerance];
//   - loops run climb-wise for an M3 cutter (clockwise round an island, counter-clockwise
//     inside a pocket); an inside corner is a sharp corner of the path (the part keeps a
//     fillet of the cutter's radius), an outside corner an arc;
//   - faces at the tip's own height are floors, not walls; a flange above the tip within
//     the flutes pushes the path out; a holder wider than the cutter keeps the path off a
//     wall taller than the flutes and shank.

#include "toolpaths/wall_finish.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "test_meshes.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Triangle;
using geometry::Vec3;
using Mesh = std::vector<Triangle>;

constexpr double kInf = std::numeric_limits<double>::infinity();
const WallFinishOptions kOptions{};  // chord 0.001, clearance 0.0002
// The integer grid (10 nm) and the offset's own rounding.
constexpr double kRounding = 2e-5;

// A solid of revolution about the Z axis through `c`: the profile (radius, z) from the axis
// at the bottom to the axis at the top, turned in n steps (the STL's n-gons).
Mesh revolved(const std::vector<Point2>& profile, int n, Point2 c = {0, 0}) {
  Mesh m;
  auto at = [&](Point2 rz, int i) {
    const double a = 2 * std::numbers::pi * (i % n) / n;
    return Vec3{c.x + rz.x * std::cos(a), c.y + rz.x * std::sin(a), rz.y};
  };
  for (std::size_t j = 0; j + 1 < profile.size(); ++j)
    for (int i = 0; i < n; ++i) {
      const Vec3 a = at(profile[j], i), b = at(profile[j], i + 1), d = at(profile[j + 1], i), e = at(profile[j + 1], i + 1);
      if (profile[j].x > 0) m.push_back({a, b, e});
      if (profile[j + 1].x > 0) m.push_back({a, e, d});
    }
  return m;
}

// A block with a rectangular pocket through it from z0 to z1: the frame between them.
Mesh frame(const std::vector<Point2>& outer, const std::vector<Point2>& inner, double z0, double z1) {
  Mesh m;
  for (int i = 0; i < 4; ++i) {
    const Point2 a = outer[i], b = outer[(i + 1) % 4], p = inner[i], q = inner[(i + 1) % 4];
    for (const auto& [u, v] : {std::pair{a, b}, std::pair{q, p}}) {
      m.push_back({Vec3{u.x, u.y, z0}, Vec3{v.x, v.y, z0}, Vec3{v.x, v.y, z1}});
      m.push_back({Vec3{u.x, u.y, z0}, Vec3{v.x, v.y, z1}, Vec3{u.x, u.y, z1}});
    }
    for (const double z : {z0, z1}) {
      m.push_back({Vec3{a.x, a.y, z}, Vec3{b.x, b.y, z}, Vec3{q.x, q.y, z}});
      m.push_back({Vec3{a.x, a.y, z}, Vec3{q.x, q.y, z}, Vec3{p.x, p.y, z}});
    }
  }
  return m;
}

Mesh joined(Mesh a, const Mesh& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

double segment_distance(Point2 p, Point2 a, Point2 b) {
  const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(p.x - a.x - t * dx, p.y - a.y - t * dy);
}

bool inside_polygon(Point2 p, const std::vector<Point2>& poly) {
  bool in = false;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i) {
    const Point2 a = poly[i], b = poly[(i + 1) % n];
    if ((a.y > p.y) != (b.y > p.y) && a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) > p.x) in = !in;
  }
  return in;
}

// Distance from p to the filled polygon (0 inside).
double distance_to(Point2 p, const std::vector<Point2>& poly) {
  if (inside_polygon(p, poly)) return 0;
  double d = kInf;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i) d = std::min(d, segment_distance(p, poly[i], poly[(i + 1) % n]));
  return d;
}

// Every vertex of the loop and 8 points along each of its chords.
template <class Fn>
void along_loop(const std::vector<Point2>& loop, Fn fn) {
  for (std::size_t i = 0, n = loop.size(); i < n; ++i)
    for (int j = 0; j < 8; ++j) {
      const double t = j / 8.0;
      const Point2 a = loop[i], b = loop[(i + 1) % n];
      fn(Point2{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
    }
}

double signed_area(const std::vector<Point2>& loop) {
  double a = 0;
  for (std::size_t i = 0, n = loop.size(); i < n; ++i)
    a += loop[i].x * loop[(i + 1) % n].y - loop[(i + 1) % n].x * loop[i].y;
  return a / 2;
}

// The stand-off every point of a loop must have from the limiting wall at radius r.
void expect_stand_off(double d, double r, Point2 where) {
  EXPECT_GE(d, r + kOptions.clearance - kRounding) << "gouge at (" << where.x << ", " << where.y << ")";
  EXPECT_LE(d, r + kOptions.clearance + kOptions.chord_tolerance + kRounding)
      << "excess at (" << where.x << ", " << where.y << ")";
}

// A flat cutter of radius r, flutes `flute`, shank as wide up to `flute + shank`, then the holder.
std::vector<ToolBand> flat(double r, double flute, double shank = 20, double holder_r = 0) {
  return {{0, flute, r}, {flute, flute + shank, r}, {flute + shank, kInf, std::max(r, holder_r)}};
}

TEST(WallFinish, ACylinderIsFollowedAtItsRadiusPlusTheCuttersOnTheStlPolygon) {
  const int n = 48;
  const double R = 10, r = 3;
  const std::vector<Point2> gon = regular(n, R, {25, 25});
  const TipKeepOut f = tip_keep_out(prism(gon, 0, 30), 12.5, flat(r, 12), kOptions);
  ASSERT_EQ(f.loops().size(), 1u) << "one loop round the island, no hole inside it";
  const auto& loop = f.loops()[0];
  EXPECT_LT(signed_area(loop), 0) << "clockwise round an island: climb milling with M3";
  double rmin = kInf, rmax = 0;
  along_loop(loop, [&](Point2 p) {
    expect_stand_off(distance_to(p, gon), r, p);
    const double rho = std::hypot(p.x - 25, p.y - 25);
    rmin = std::min(rmin, rho), rmax = std::max(rmax, rho);
  });
  // The polygon's offset lies between the inscribed and the circumscribed circle plus r.
  EXPECT_GE(rmin, R * std::cos(std::numbers::pi / n) + r + kOptions.clearance - kRounding);
  EXPECT_LE(rmax, R + r + kOptions.clearance + kOptions.chord_tolerance + kRounding);
  EXPECT_NEAR(rmax, R + r, 0.002) << "at the polygon's vertices the path is on the circle of R + r";
}

TEST(WallFinish, AWallSpanningTheWholeBandIsSeenByItsCrossSection) {
  // A cutter alone (no body above it to see the top): the wall has no facet but vertical
  // ones within the band; the cross-section under it fills the island.
  const double R = 10, r = 3;
  const std::vector<Point2> gon = regular(48, R);
  const TipKeepOut f = tip_keep_out(prism(gon, 0, 30), 12.5, {{0, 12, r}}, kOptions);
  ASSERT_EQ(f.loops().size(), 1u);
  along_loop(f.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, gon), r, p); });
  EXPECT_TRUE(f.contains({0, 0}));
  // A tube: its bore stays free.
  const Mesh tube = frame(rectangle(-10, -10, 10, 10), rectangle(-5, -5, 5, 5), 0, 30);
  const TipKeepOut g = tip_keep_out(tube, 12.5, {{0, 12, 1}}, kOptions);
  EXPECT_EQ(g.loops().size(), 2u);
  EXPECT_FALSE(g.contains({0, 0}));
  EXPECT_TRUE(g.contains({7.5, 0}));
}

TEST(WallFinish, ABoxIsFollowedByARoundedRectangle) {
  const double r = 2;
  const std::vector<Point2> rect = rectangle(0, 0, 30, 20);
  const TipKeepOut f = tip_keep_out(prism(rect, 0, 10), 5, flat(r, 8), kOptions);
  ASSERT_EQ(f.loops().size(), 1u);
  const auto& loop = f.loops()[0];
  double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
  along_loop(loop, [&](Point2 p) {
    expect_stand_off(distance_to(p, rect), r, p);
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  });
  // Straight sides at exactly the offset; corners are arcs of it.
  const double off = r + kOptions.clearance + kOptions.chord_tolerance;
  EXPECT_NEAR(x0, -off, kRounding);
  EXPECT_NEAR(x1, 30 + off, kRounding);
  EXPECT_NEAR(y0, -off, kRounding);
  EXPECT_NEAR(y1, 20 + off, kRounding);
  double length = 0;
  for (std::size_t i = 0; i < loop.size(); ++i)
    length += std::hypot(loop[(i + 1) % loop.size()].x - loop[i].x, loop[(i + 1) % loop.size()].y - loop[i].y);
  EXPECT_NEAR(length, 2 * (30 + 20) + 2 * std::numbers::pi * off, 0.01);
  // Outside a corner the path is an arc round it: a point at 45 degrees is off by r.
  bool on_corner_arc = false;
  along_loop(loop, [&](Point2 p) {
    if (p.x > 30 && p.y > 20 && std::abs((p.x - 30) - (p.y - 20)) < 0.05) on_corner_arc = true;
  });
  EXPECT_TRUE(on_corner_arc);
}

TEST(WallFinish, AnInsideCornerIsASharpCornerOfThePathAtTheCuttersRadiusFromBothWalls) {
  const double r = 2.5;
  // An L: the inside corner at (10, 10).
  const std::vector<Point2> ell{{0, 0}, {20, 0}, {20, 10}, {10, 10}, {10, 20}, {0, 20}};
  const TipKeepOut f = tip_keep_out(prism(ell, 0, 10), 2, flat(r, 10), kOptions);
  ASSERT_EQ(f.loops().size(), 1u);
  const auto& loop = f.loops()[0];
  EXPECT_LT(signed_area(loop), 0);
  along_loop(loop, [&](Point2 p) { expect_stand_off(distance_to(p, ell), r, p); });
  // The path's vertex in the corner touches both walls: the part keeps a fillet of r there.
  const double off = r + kOptions.clearance + kOptions.chord_tolerance;
  double nearest = kInf;
  for (const Point2& p : loop) nearest = std::min(nearest, std::hypot(p.x - (10 + off), p.y - (10 + off)));
  EXPECT_LT(nearest, kRounding);
}

TEST(WallFinish, APocketIsFollowedInsideCounterClockwise) {
  const double r = 2;
  const std::vector<Point2> outer = rectangle(0, 0, 40, 30), inner = rectangle(10, 8, 30, 22);
  const TipKeepOut f = tip_keep_out(frame(outer, inner, 0, 12), 4, flat(r, 10), kOptions);
  ASSERT_EQ(f.loops().size(), 2u) << "round the block and inside the pocket";
  int inside = 0;
  for (const auto& loop : f.loops()) {
    if (signed_area(loop) > 0) {
      ++inside;
      // Inside the pocket: the pocket shrunk by r, sharp corners.
      along_loop(loop, [&](Point2 p) {
        const double d = std::min({p.x - 10, 30 - p.x, p.y - 8, 22 - p.y});
        expect_stand_off(d, r, p);
      });
      EXPECT_EQ(loop.size(), 4u) << "a rectangle: the pocket's corners are inside corners";
    } else {
      along_loop(loop, [&](Point2 p) { expect_stand_off(distance_to(p, outer), r, p); });
    }
  }
  EXPECT_EQ(inside, 1) << "the pocket's loop runs counter-clockwise: climb milling inside";
  // The pocket's middle is free, the frame is not.
  EXPECT_FALSE(f.contains({20, 15}));
  EXPECT_TRUE(f.contains({5, 15}));
}

TEST(WallFinish, AFaceAtTheTipsHeightIsAFloorNotAWall) {
  const double r = 3;
  // A boss of radius 5 on a 40 x 40 base whose top is at z = 10, the tip on it.
  const std::vector<Point2> boss = regular(32, 5, {20, 20});
  const Mesh part = joined(prism(rectangle(0, 0, 40, 40), 0, 10), prism(boss, 10, 20));
  // (Two touching boxes: the base's top and the boss's bottom overlap inside the boss,
  // even-odd, as a stitched mesh would have them.)
  const TipKeepOut on_floor = tip_keep_out(part, 10, flat(r, 15), kOptions);
  ASSERT_EQ(on_floor.loops().size(), 1u);
  along_loop(on_floor.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, boss), r, p); });
  // A hair lower the base is a wall again.
  const TipKeepOut below = tip_keep_out(part, 10 - 0.01, flat(r, 15), kOptions);
  ASSERT_EQ(below.loops().size(), 1u);
  along_loop(below.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, rectangle(0, 0, 40, 40)), r, p); });
}

TEST(WallFinish, AFlangeAboveTheTipWithinTheFlutesPushesThePathOut) {
  // The flanged hub: a hub of radius 10 up to z = 30, a flange of radius 25 over 30..35.
  const int n = 48;
  const double r = 5;
  const Mesh hub = revolved({{0, 0}, {10, 0}, {10, 30}, {25, 30}, {25, 35}, {0, 35}}, n);
  const std::vector<Point2> hub_gon = regular(n, 10), flange_gon = regular(n, 25);
  // Flutes of 22 from z = 10 reach the flange: the side must stay outside it.
  const TipKeepOut reached = tip_keep_out(hub, 10, flat(r, 22, 50, 21), kOptions);
  ASSERT_EQ(reached.loops().size(), 1u);
  along_loop(reached.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, flange_gon), r, p); });
  // From z = 5 the flutes end below the flange but the shank (as wide) reaches it.
  const TipKeepOut shank = tip_keep_out(hub, 5, flat(r, 22, 50, 21), kOptions);
  ASSERT_EQ(shank.loops().size(), 1u);
  along_loop(shank.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, flange_gon), r, p); });
  // Upside down (the flange at the bottom, turned as the -Z setup sees it): at z = -20 the
  // tool is on the hub, which the flange below does not concern.
  Mesh turned = hub;
  for (Triangle& t : turned)
    for (Vec3& v : t) v = {v.x, -v.y, -v.z};
  const TipKeepOut above_flange = tip_keep_out(turned, -20, flat(r, 22, 50, 21), kOptions);
  ASSERT_EQ(above_flange.loops().size(), 1u);
  along_loop(above_flange.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, hub_gon), r, p); });
  // On the flange's face (z = -30) the rim is the wall below: at -32 the rim.
  const TipKeepOut rim = tip_keep_out(turned, -32, flat(r, 22, 50, 21), kOptions);
  ASSERT_EQ(rim.loops().size(), 1u);
  along_loop(rim.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, flange_gon), r, p); });
}

TEST(WallFinish, ASlopedWallIsFollowedWhereItIsWidestWithinTheFlutes) {
  // A frustum: radius 10 at z = 0 to 5 at z = 10, as a 64-gon.
  const int n = 64;
  const double r = 2;
  const Mesh cone = revolved({{0, 0}, {10, 0}, {5, 10}, {0, 10}}, n);
  // At z = 4 the widest section within the flutes is at their bottom, floor_slack above
  // the tip: radius 8 less half the slack.
  const TipKeepOut f = tip_keep_out(cone, 4, flat(r, 6), kOptions);
  ASSERT_EQ(f.loops().size(), 1u);
  const double radius = 10 - 0.5 * (4 + kOptions.floor_slack);
  along_loop(f.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, regular(n, radius)), r, p); });
}

TEST(WallFinish, AHolderWiderThanTheCutterKeepsOffATallWall) {
  // A tower of radius 10, 100 mm tall; flutes 10, shank (r) 20, holder r = 15 from 30 up.
  const int n = 48;
  const double r = 3, holder = 15;
  const std::vector<Point2> gon = regular(n, 10);
  const Mesh tower = prism(gon, 0, 100);
  const TipKeepOut deep = tip_keep_out(tower, 50, flat(r, 10, 20, holder), kOptions);
  ASSERT_EQ(deep.loops().size(), 1u);
  along_loop(deep.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, gon), holder, p); });
  // Within 30 mm of the top the holder clears it: the cutter touches the wall.
  const TipKeepOut high = tip_keep_out(tower, 75, flat(r, 10, 20, holder), kOptions);
  ASSERT_EQ(high.loops().size(), 1u);
  along_loop(high.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, gon), r, p); });
}

TEST(WallFinish, AWallAsTallAsTheFlutesIsTouchedNotEnteredByTheWiderShank) {
  // A 10 mm wall above the tip, flutes 10 mm, then a shank of r = 3: at the wall's foot the
  // shank's bottom stands on the wall's top edge and the cutter reaches the whole wall.
  const double r = 2;
  const std::vector<Point2> rect = rectangle(0, 0, 30, 2.5);
  const std::vector<ToolBand> tool{{0, 10, r}, {10, 50, 3}, {50, kInf, 20}};
  const TipKeepOut foot = tip_keep_out(prism(rect, 2, 12), 2, tool, kOptions);
  ASSERT_EQ(foot.loops().size(), 1u);
  along_loop(foot.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, rect), r, p); });
  // A hair lower, the shank would enter the wall's top: it keeps the shank's radius off.
  const TipKeepOut lower = tip_keep_out(prism(rect, 0, 12), 1.99, tool, kOptions);
  ASSERT_EQ(lower.loops().size(), 1u);
  along_loop(lower.loops()[0], [&](Point2 p) { expect_stand_off(distance_to(p, rect), 3, p); });
}

TEST(WallFinish, NothingAboveTheTipGivesNoLoops) {
  const TipKeepOut f = tip_keep_out(prism(rectangle(0, 0, 10, 10), 0, 10), 10, flat(2, 8), kOptions);
  EXPECT_TRUE(f.empty()) << "the tip on the top face: nothing to keep out of";
  EXPECT_TRUE(tip_keep_out({}, 0, flat(2, 8), kOptions).empty());
}

TEST(WallFinish, SegmentsAreClearExactlyWhenTheyStayOutOfTheRegion) {
  const double r = 2;
  const TipKeepOut f = tip_keep_out(prism(rectangle(0, 0, 10, 10), 0, 10), 5, flat(r, 8), kOptions);
  const double off = r + kOptions.clearance + kOptions.chord_tolerance;
  // Square onto the wall's path from outside: clear; one step further in: not.
  EXPECT_TRUE(f.segment_clear({-5, 5}, {-off, 5}));
  EXPECT_FALSE(f.segment_clear({-5, 5}, {-off + 0.001, 5}));
  // Past the box at a distance, and through its corner region.
  EXPECT_TRUE(f.segment_clear({-5, -off - 0.01}, {15, -off - 0.01}));
  EXPECT_FALSE(f.segment_clear({-5, -5}, {15, 15}));
  // Both ends outside, the middle through the region.
  EXPECT_FALSE(f.segment_clear({5, -5}, {5, 15}));
  EXPECT_FALSE(f.contains({-off - 0.001, 5}));
  EXPECT_TRUE(f.contains({-off + 0.001, 5}));
}

TEST(WallFinish, GrowingTheRegionMovesItsStraightSidesOut) {
  const TipKeepOut f = tip_keep_out(prism(rectangle(0, 0, 10, 10), 0, 10), 5, flat(2, 8), kOptions);
  const TipKeepOut g = f.grown(0.25);
  const double off = 2 + kOptions.clearance + kOptions.chord_tolerance;
  EXPECT_TRUE(g.contains({-off - 0.2, 5}));
  EXPECT_FALSE(g.contains({-off - 0.3, 5}));
  ASSERT_EQ(g.loops().size(), 1u);
  EXPECT_LT(signed_area(g.loops()[0]), 0) << "loops keep the region on their right";
}

TEST(WallFinish, OnlyFlatToolsHaveBands) {
  config::CuttingTool t;
  t.type = config::ToolType::Flat;
  t.diameter = 10;
  t.flute_length = 22;
  t.shank = {8, 50};
  t.holder = {42, 60};
  const std::vector<ToolBand> b = flat_tool_bands(t);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_DOUBLE_EQ(b[0].radius, 5);
  EXPECT_DOUBLE_EQ(b[0].to, 22);
  EXPECT_DOUBLE_EQ(b[1].radius, 5) << "a neck as narrow as 8 mm counts as the cutter above it (vertical moves)";
  EXPECT_DOUBLE_EQ(b[1].to, 72);
  EXPECT_DOUBLE_EQ(b[2].radius, 21);
  EXPECT_TRUE(std::isinf(b[2].to));
  t.type = config::ToolType::Ball;
  EXPECT_TRUE(flat_tool_bands(t).empty());
}

// A near-net deposit's layer: the section of a frame (a block with a pocket) shrunk by half
// a bead is where the bead's axis may go; a line across it is cut into the pieces that lie
// there, and a point off it goes to its nearest edge.
TEST(WallFinish, ASectionShrunkByHalfABeadHoldsTheBeadsAxisAndCutsLinesAtItsEdges) {
  const Mesh block = frame(rectangle(0, 0, 20, 10), rectangle(8, 2, 12, 8), 0, 5);
  const TipKeepOut axis = section_shrunk(block, {2.0, 2.5}, 0.75);
  EXPECT_TRUE(axis.contains({0.76, 5}));
  EXPECT_FALSE(axis.contains({0.74, 5}));
  EXPECT_FALSE(axis.contains({10, 5})) << "the pocket, grown by half a bead, holds no axis";
  EXPECT_TRUE(axis.contains({7.24, 5}));
  // Across the block through the pocket: two pieces, each ending half a bead from a wall.
  const auto pieces = axis.pieces_inside({-3, 5}, {23, 5});
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_NEAR(pieces[0].first.x, 0.75, 1e-3);
  EXPECT_NEAR(pieces[0].second.x, 7.25, 1e-3);
  EXPECT_NEAR(pieces[1].first.x, 12.75, 1e-3);
  EXPECT_NEAR(pieces[1].second.x, 19.25, 1e-3);
  EXPECT_TRUE(axis.pieces_inside({9, 5}, {11, 5}).empty());
  const Point2 edge = axis.nearest_on_boundary({0.5, 5});
  EXPECT_NEAR(edge.x, 0.75, 1e-3);
  EXPECT_NEAR(edge.y, 5, 1e-9);
  // Above the block there is no section: no place for an axis.
  EXPECT_TRUE(section_shrunk(block, {6.0}, 0.75).empty());
}

}  // namespace
}  // namespace hybridctl::toolpaths
