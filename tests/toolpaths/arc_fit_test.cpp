// Arc fitting (toolpaths/arc_fit.hpp, docs/toolpaths.md "Arc fitting"), as specifications:
// what becomes an arc and what stays lines, and that every arc made is within the chord
// tolerance of the moves it replaces, both ways. The bound is checked independently of
// the fitter: each arc produced is sampled densely from its own centre, direction and ends,
// and each sample's distance to the original polyline is measured; each original point and
// chord middle is measured against the arc the same way.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "config/machine_loader.hpp"
#include "gcode/interpreter.hpp"
#include "gcode/post.hpp"
#include "toolpaths/arc_fit.hpp"

namespace {

using namespace hybridctl;
using namespace hybridctl::toolpaths;
using geometry::Vec3;

constexpr double kPi = std::numbers::pi;

PathMove feed_to(double x, double y, double z, double feed = 600) {
  PathMove m;
  m.kind = MoveKind::Feed;
  m.to = {x, y, z};
  m.feed = feed;
  m.process_on = true;
  return m;
}

// Feed moves along the circle of `radius` about (cx, cy) at height z, from angle a0 over
// `sweep` (counter-clockwise > 0) in `chords` equal chords; the start point is not a move.
std::vector<PathMove> circle_chords(double cx, double cy, double radius, double z, double a0, double sweep, int chords) {
  std::vector<PathMove> out;
  for (int i = 1; i <= chords; ++i) {
    const double a = a0 + sweep * i / chords;
    out.push_back(feed_to(cx + radius * std::cos(a), cy + radius * std::sin(a), z));
  }
  return out;
}

double distance_to_segment(const Vec3& q, const Vec3& a, const Vec3& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
  const double t = len2 > 0 ? std::clamp(((q.x - a.x) * dx + (q.y - a.y) * dy) / len2, 0.0, 1.0) : 0.0;
  return std::hypot(a.x + t * dx - q.x, a.y + t * dy - q.y);
}

// The points of an arc move from `from`, sampled every `step` radians or finer, ends included:
// from its own centre and direction, as a controller would run it.
std::vector<Vec3> sample_arc(const Vec3& from, const PathMove& arc, double step = 0.002) {
  const double cx = arc.centre.x, cy = arc.centre.y;
  const double r = std::hypot(from.x - cx, from.y - cy);
  const double a0 = std::atan2(from.y - cy, from.x - cx), a1 = std::atan2(arc.to.y - cy, arc.to.x - cx);
  double sweep = a1 - a0;
  if (arc.kind == MoveKind::ArcCcw)
    while (sweep <= 0) sweep += 2 * kPi;
  else
    while (sweep >= 0) sweep -= 2 * kPi;
  const int n = std::max(8, int(std::ceil(std::abs(sweep) / step)));
  std::vector<Vec3> out;
  for (int i = 0; i <= n; ++i) {
    const double a = a0 + sweep * i / n;
    out.push_back({cx + r * std::cos(a), cy + r * std::sin(a), from.z});
  }
  return out;
}

// Distance from q to the arc (from `from`): through the samples, which are dense enough
// (0.002 rad on radii of tens of mm: chords 1e-5 mm off the arc) to measure to 1e-5 mm.
double distance_to_arc(const Vec3& q, const std::vector<Vec3>& samples) {
  double best = 1e300;
  for (std::size_t i = 0; i + 1 < samples.size(); ++i) best = std::min(best, distance_to_segment(q, samples[i], samples[i + 1]));
  return best;
}

struct Bounds {
  double arc_to_lines = 0;  // farthest sample of an arc from the lines it replaced
  double lines_to_arc = 0;  // farthest original point or chord middle from its arc
  double outside_arc = 0;   // farthest point of the lines outside the arc's circle (the arc passing inside them)
  int arcs = 0;
};

// Walks `fitted` against `original` (both from `start`): every move that is not an arc
// must be the original's next move unchanged; an arc replaces the original moves up to the
// one ending where it ends, and is measured against them both ways.
Bounds measure(const Vec3& start, const std::vector<PathMove>& original, const std::vector<PathMove>& fitted) {
  Bounds b;
  Vec3 at = start;
  std::size_t k = 0;
  for (const PathMove& m : fitted) {
    EXPECT_LT(k, original.size());
    if (k >= original.size()) break;
    if (m.kind != MoveKind::ArcCw && m.kind != MoveKind::ArcCcw) {
      EXPECT_EQ(m.kind, original[k].kind);
      EXPECT_EQ(m.to, original[k].to);
      EXPECT_EQ(m.feed, original[k].feed);
      at = m.to;
      ++k;
      continue;
    }
    ++b.arcs;
    // The original moves it replaces: up to the one ending exactly where it ends.
    std::vector<Vec3> lines{at};
    while (k < original.size() && !(original[k].to == m.to)) lines.push_back(original[k++].to);
    EXPECT_LT(k, original.size()) << "an arc that ends at no original point";
    if (k >= original.size()) break;
    lines.push_back(original[k++].to);
    EXPECT_GE(lines.size(), 4u) << "an arc replaces at least 3 chords";
    // Both radii agree: the centre is as far from the start as from the end.
    EXPECT_NEAR(std::hypot(at.x - m.centre.x, at.y - m.centre.y), std::hypot(m.to.x - m.centre.x, m.to.y - m.centre.y), 1e-9);
    const std::vector<Vec3> samples = sample_arc(at, m);
    for (const Vec3& s : samples) {
      double d = 1e300;
      for (std::size_t i = 0; i + 1 < lines.size(); ++i) d = std::min(d, distance_to_segment(s, lines[i], lines[i + 1]));
      b.arc_to_lines = std::max(b.arc_to_lines, d);
    }
    const double r = std::hypot(at.x - m.centre.x, at.y - m.centre.y);
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) {
      const Vec3 mid{(lines[i].x + lines[i + 1].x) / 2, (lines[i].y + lines[i + 1].y) / 2, lines[i].z};
      b.lines_to_arc = std::max({b.lines_to_arc, distance_to_arc(lines[i], samples), distance_to_arc(mid, samples)});
      for (int t = 0; t <= 16; ++t) {
        const double x = lines[i].x + (lines[i + 1].x - lines[i].x) * t / 16, y = lines[i].y + (lines[i + 1].y - lines[i].y) * t / 16;
        b.outside_arc = std::max(b.outside_arc, std::hypot(x - m.centre.x, y - m.centre.y) - r);
      }
    }
    at = m.to;
  }
  EXPECT_EQ(k, original.size()) << "the fitted path ends where the original does";
  return b;
}

// The fitted arcs stand within `tolerance` of the lines both ways, and pass inside them by
// no more than the inward tolerance (0.0001 mm).
void expect_faithful(const Bounds& b, double tolerance) {
  EXPECT_LE(b.arc_to_lines, tolerance);
  EXPECT_LE(b.lines_to_arc, tolerance);
  EXPECT_LE(b.outside_arc, 0.0001);
}

int count(const std::vector<PathMove>& moves, MoveKind kind) {
  return int(std::count_if(moves.begin(), moves.end(), [&](const PathMove& m) { return m.kind == kind; }));
}

// ---------------------------------------------------------------------------------------
// What becomes an arc.

// A finishing pass round a round boss, as Clipper's round offsets make it: chords on a
// circle of 15 mm, 0.0004 mm inside their arc at their middles. Half of it is one
// counter-clockwise arc, within 0.001 mm of the chords both ways.
TEST(ArcFit, DenseChordsOfACircleBecomeOneArcWithinTheTolerance) {
  const Vec3 start{25, 10, -3};
  const std::vector<PathMove> half = circle_chords(10, 10, 15, -3, 0, kPi, 216);
  ArcFitStats stats;
  const std::vector<PathMove> fitted = fit_arcs(start, half, {}, &stats);
  ASSERT_EQ(fitted.size(), 1u);
  EXPECT_EQ(fitted[0].kind, MoveKind::ArcCcw);
  EXPECT_EQ(fitted[0].to, half.back().to) << "the end point is exactly the original's";
  EXPECT_NEAR(fitted[0].centre.x, 10, 1e-9);
  EXPECT_NEAR(fitted[0].centre.y, 10, 1e-9);
  EXPECT_EQ(stats.arcs, 1u);
  EXPECT_EQ(stats.moves_replaced, 216u);
  const Bounds b = measure(start, half, fitted);
  expect_faithful(b, 0.001);
}

// The flanged hub's STL is a 48-gon: on its 10 mm radius each side is 0.0214 mm off the
// circle at its middle. At the default 0.001 mm no arc stays that close to the polygon, so
// it stays lines; at 0.025 mm it is arcs (a full turn: two of them), each within 0.025 mm of
// the polygon both ways.
TEST(ArcFit, A48GonIsFittedOnlyAtAToleranceAboveItsSagitta) {
  const Vec3 start{20, 0, 0};
  const std::vector<PathMove> polygon = circle_chords(10, 0, 10, 0, 0, 2 * kPi, 48);
  EXPECT_EQ(count(fit_arcs(start, polygon), MoveKind::Feed), 48) << "0.001 mm: lines";

  ArcFitOptions loose;
  loose.chord_tolerance = 0.025;
  const std::vector<PathMove> fitted = fit_arcs(start, polygon, loose);
  EXPECT_EQ(count(fitted, MoveKind::Feed), 0);
  EXPECT_EQ(count(fitted, MoveKind::ArcCcw), 2) << "a full turn is two arcs (270 and 90 degrees)";
  const Bounds b = measure(start, polygon, fitted);
  EXPECT_EQ(b.arcs, 2);
  expect_faithful(b, 0.025);
}

// A closed circle never becomes one arc (a move that ends where it starts is a full turn
// to a controller, or nothing): it is split, each arc under 360 degrees.
TEST(ArcFit, AFullCircleIsSplitIntoTwoArcs) {
  const Vec3 start{5, 0, 1};
  const std::vector<PathMove> circle = circle_chords(0, 0, 5, 1, 0, -2 * kPi, 360);  // clockwise
  const std::vector<PathMove> fitted = fit_arcs(start, circle);
  ASSERT_EQ(fitted.size(), 2u);
  EXPECT_EQ(fitted[0].kind, MoveKind::ArcCw);
  EXPECT_EQ(fitted[1].kind, MoveKind::ArcCw);
  EXPECT_EQ(fitted[1].to, circle.back().to);
  // Each arc's sweep: 270 and 90 degrees.
  const double mid = std::atan2(fitted[0].to.y, fitted[0].to.x);
  EXPECT_NEAR(mid, kPi / 2, 1e-9) << "270 degrees clockwise from 0 ends at 90";
  const Bounds b = measure(start, circle, fitted);
  expect_faithful(b, 0.001);
}

// The direction is the turn's: counter-clockwise chords make G3, clockwise ones G2.
TEST(ArcFit, TheDirectionIsTheTurnOfTheChords) {
  const Vec3 start{10, 0, 0};
  const auto ccw = fit_arcs(start, circle_chords(0, 0, 10, 0, 0, kPi / 2, 180));
  ASSERT_EQ(ccw.size(), 1u);
  EXPECT_EQ(ccw[0].kind, MoveKind::ArcCcw);
  const auto cw = fit_arcs(start, circle_chords(0, 0, 10, 0, 0, -kPi / 2, 180));
  ASSERT_EQ(cw.size(), 1u);
  EXPECT_EQ(cw[0].kind, MoveKind::ArcCw);
  EXPECT_NEAR(cw[0].to.y, -10, 1e-12);
}

// The arc may stand out of the moves by the chord tolerance (away from its centre, as an
// arc does from its chords), but never passes inside them by more than inward_tolerance
// (0.0001 mm): a wall finishing pass's chords stand off the design by only 0.0002 mm.
// A quarter circle whose 26th point lies 0.0005 mm outside it is one arc when 0.001 mm is
// allowed both ways; by default it is split so that no point is left outside an arc.
TEST(ArcFit, AnArcNeverPassesInsideTheMovesByMoreThanTheInwardTolerance) {
  const Vec3 start{10, 0, 0};
  std::vector<PathMove> bumped = circle_chords(0, 0, 10, 0, 0, kPi / 2, 100);
  const double a = kPi / 2 * 26 / 100;
  bumped[25].to = {10.0005 * std::cos(a), 10.0005 * std::sin(a), 0};
  ArcFitOptions both_ways;
  both_ways.inward_tolerance = both_ways.chord_tolerance;
  const std::vector<PathMove> loose = fit_arcs(start, bumped, both_ways);
  ASSERT_EQ(loose.size(), 1u);
  EXPECT_NEAR(measure(start, bumped, loose).outside_arc, 0.0005, 1e-6);

  const std::vector<PathMove> fitted = fit_arcs(start, bumped);
  EXPECT_GT(fitted.size(), 1u);
  const Bounds b = measure(start, bumped, fitted);
  EXPECT_LE(b.outside_arc, 0.0001);
  EXPECT_LE(b.arc_to_lines, 0.001);
  EXPECT_LE(b.lines_to_arc, 0.001);
}

// A wall finishing pass round a convex corner of the design (its vertex at the origin): a
// straight side in short pieces, the round join (the cutter's 5 mm about the vertex, in
// chords 0.00013 mm inside it), the next side along the join's tangent. The join becomes an
// arc about the vertex, the sides stay lines, and no arc comes nearer the vertex than the
// moves did (less 0.0001 mm).
TEST(ArcFit, ACornersRoundJoinBecomesAnArcThatComesNoNearerTheDesign) {
  const Vec3 start{-1, -5, 0};
  std::vector<PathMove> pass;
  for (int i = 1; i <= 20; ++i) pass.push_back(feed_to(-1 + 0.05 * i, -5, 0));  // side along +X to (0, -5)
  for (const PathMove& m : circle_chords(0, 0, 5, 0, -kPi / 2, kPi / 6, 36)) pass.push_back(m);  // 30 degree join
  const double ex = pass.back().to.x, ey = pass.back().to.y;
  for (int i = 1; i <= 20; ++i) pass.push_back(feed_to(ex + 0.05 * i * std::cos(kPi / 6), ey + 0.05 * i * std::sin(kPi / 6), 0));
  const std::vector<PathMove> fitted = fit_arcs(start, pass);
  EXPECT_GE(count(fitted, MoveKind::ArcCcw), 1);
  EXPECT_GE(count(fitted, MoveKind::Feed), 36) << "the sides stay lines, nearly all";
  bool about_vertex = false;
  for (const PathMove& m : fitted) about_vertex |= m.kind == MoveKind::ArcCcw && std::hypot(m.centre.x, m.centre.y) < 0.01;
  EXPECT_TRUE(about_vertex);
  const Bounds b = measure(start, pass, fitted);
  EXPECT_LE(b.outside_arc, 0.0001);
  EXPECT_LE(b.lines_to_arc, 0.001);
  // Nearest approach to the vertex: the moves', and the fitted path's (arcs sampled).
  const auto nearest = [&](const std::vector<PathMove>& moves) {
    double best = 1e300;
    Vec3 at = start;
    for (const PathMove& m : moves) {
      const std::vector<Vec3> pts = m.kind == MoveKind::Feed ? std::vector<Vec3>{at, m.to} : sample_arc(at, m, 0.0002);
      for (std::size_t i = 0; i + 1 < pts.size(); ++i) best = std::min(best, distance_to_segment({0, 0, 0}, pts[i], pts[i + 1]));
      at = m.to;
    }
    return best;
  };
  EXPECT_GE(nearest(fitted), nearest(pass) - 0.0001);
}

// ---------------------------------------------------------------------------------------
// What stays lines.

// Straight runs, lattice staircases, zigzags and a wave are not circles: every move stays.
TEST(ArcFit, APolylineThatIsNotCircularStaysLines) {
  const Vec3 start{0, 0, 0};
  std::vector<std::vector<PathMove>> cases(4);
  for (int i = 1; i <= 20; ++i) cases[0].push_back(feed_to(0.5 * i, 0, 0));                        // a row
  for (int i = 1; i <= 20; ++i) cases[1].push_back(feed_to(0.5 * ((i + 1) / 2), 0.5 * (i / 2), 0));  // staircase
  for (int i = 1; i <= 20; ++i) cases[2].push_back(feed_to(1.0 * i, i % 2 ? 0.3 : 0, 0));          // zigzag
  for (int i = 1; i <= 60; ++i) cases[3].push_back(feed_to(0.2 * i, std::sin(0.2 * i) * 0.5 * std::sin(0.7 * i), 0));
  for (const auto& moves : cases) {
    const std::vector<PathMove> fitted = fit_arcs(start, moves);
    EXPECT_EQ(fitted.size(), moves.size());
    EXPECT_EQ(count(fitted, MoveKind::Feed), int(moves.size()));
  }
}

// A gentle curve whose radius is beyond max_radius (here 2 m) stays lines even where the
// chords lie on a circle.
TEST(ArcFit, ARadiusBeyondTheBoundStaysLines) {
  const std::vector<PathMove> flat = circle_chords(0, -2000, 2000, 0, kPi / 2, -0.01, 10);
  EXPECT_EQ(count(fit_arcs({0, 0, 0}, flat), MoveKind::Feed), 10);
  ArcFitOptions wide;
  wide.max_radius = 5000;
  EXPECT_EQ(fit_arcs({0, 0, 0}, flat, wide).size(), 1u);
}

// Fewer than three chords are never an arc; a run is one height, one feed, one process
// state, with comments only on its first move, and rapids are never touched.
TEST(ArcFit, RunsBreakAtHeightFeedProcessCommentsAndRapids) {
  const Vec3 start{10, 0, 0};
  const auto base = [] { return circle_chords(0, 0, 10, 0, 0, kPi, 180); };  // 1 degree chords
  EXPECT_EQ(count(fit_arcs(start, circle_chords(0, 0, 10, 0, 0, kPi / 90, 2)), MoveKind::Feed), 2) << "two chords";
  EXPECT_EQ(fit_arcs(start, circle_chords(0, 0, 10, 0, 0, kPi / 60, 3)).size(), 1u) << "three chords";

  std::vector<PathMove> commented = base();
  commented[0].comment = "finish wall";
  const auto first = fit_arcs(start, commented);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].comment, "finish wall") << "the first move's comment goes on the arc";

  const auto two_arcs = [&](std::vector<PathMove> moves) {
    const auto fitted = fit_arcs(start, moves);
    return count(fitted, MoveKind::ArcCcw) == 2 && fitted.size() == 2;
  };
  std::vector<PathMove> m = base();
  m[90].comment = "lead";
  EXPECT_TRUE(two_arcs(m)) << "a comment inside starts a new run";
  m = base();
  for (std::size_t i = 90; i < m.size(); ++i) m[i].feed = 300;
  EXPECT_TRUE(two_arcs(m)) << "another feed starts a new run";
  m = base();
  for (std::size_t i = 90; i < m.size(); ++i) m[i].process_on = false;
  EXPECT_TRUE(two_arcs(m)) << "deposition switched starts a new run";

  m = base();
  m[90].kind = MoveKind::Rapid;
  const auto rapid = fit_arcs(start, m);
  ASSERT_EQ(rapid.size(), 3u);
  EXPECT_EQ(rapid[1].kind, MoveKind::Rapid);
  EXPECT_EQ(rapid[1].to, m[90].to) << "a rapid stays as it is";

  // A helix (a ramp round a circle) is not fitted: arcs are planar here.
  std::vector<PathMove> helix = base();
  for (std::size_t i = 0; i < helix.size(); ++i) helix[i].to.z = -0.01 * double(i + 1);
  EXPECT_EQ(count(fit_arcs(start, helix), MoveKind::Feed), int(helix.size()));
}

// ---------------------------------------------------------------------------------------
// Mixed paths and the whole toolpath.

// A slot's wall pass (a stadium): a straight side, a half circle of chords, the other
// side, the other half circle: line, arc, line, arc, each arc within the tolerance.
TEST(ArcFit, APathMixingLinesAndArcsKeepsTheLinesAndFitsTheArcs) {
  const Vec3 start{0, -5, 2};
  std::vector<PathMove> stadium;
  stadium.push_back(feed_to(20, -5, 2));
  for (const PathMove& m : circle_chords(20, 0, 5, 2, -kPi / 2, kPi, 128)) stadium.push_back(m);
  stadium.push_back(feed_to(0, 5, 2));
  for (const PathMove& m : circle_chords(0, 0, 5, 2, kPi / 2, kPi, 128)) stadium.push_back(m);
  const std::vector<PathMove> fitted = fit_arcs(start, stadium);
  ASSERT_EQ(fitted.size(), 4u);
  EXPECT_EQ(fitted[0].kind, MoveKind::Feed);
  EXPECT_EQ(fitted[1].kind, MoveKind::ArcCcw);
  EXPECT_EQ(fitted[2].kind, MoveKind::Feed);
  EXPECT_EQ(fitted[3].kind, MoveKind::ArcCcw);
  const Bounds b = measure(start, stadium, fitted);
  EXPECT_EQ(b.arcs, 2);
  expect_faithful(b, 0.001);
}

// Chords that are not equal and not exactly on a circle (points rounded to 0.00001 mm, as
// Clipper's integer grid of 10 nm leaves them) still fit, within the tolerance.
TEST(ArcFit, UnevenChordsOffTheCircleByLessThanTheToleranceFit) {
  const Vec3 start{8, 3, 0};
  std::vector<PathMove> moves;
  double a = 0;
  for (int i = 1; i <= 40; ++i) {
    a += 0.005 + 0.004 * ((i * 7) % 5);
    const double x = 3 + 5 * std::cos(a), y = 3 + 5 * std::sin(a);
    moves.push_back(feed_to(std::round(x * 1e5) / 1e5, std::round(y * 1e5) / 1e5, 0));
  }
  const std::vector<PathMove> fitted = fit_arcs(start, moves);
  EXPECT_LE(fitted.size(), 2u);
  const Bounds b = measure(start, moves, fitted);
  EXPECT_GE(b.arcs, 1);
  expect_faithful(b, 0.001);
}

// The toolpath form keeps everything but the moves, and starts from Toolpath::start.
TEST(ArcFit, AToolpathIsFittedFromItsStart) {
  Toolpath path;
  path.instrument = "T1";
  path.start = {10, 0, 5};
  path.safe_z = 5;
  path.warnings = {"kept"};
  PathMove down = feed_to(10, 0, 0);
  down.comment = "plunge";
  path.moves.push_back(down);
  for (const PathMove& m : circle_chords(0, 0, 10, 0, 0, kPi, 180)) path.moves.push_back(m);
  PathMove up;
  up.kind = MoveKind::Rapid;
  up.to = {-10, 0, 5};
  path.moves.push_back(up);
  const Toolpath fitted = fit_arcs(path);
  ASSERT_EQ(fitted.moves.size(), 3u);
  EXPECT_EQ(fitted.moves[0].comment, "plunge");
  EXPECT_EQ(fitted.moves[1].kind, MoveKind::ArcCcw);
  EXPECT_EQ(fitted.moves[2].kind, MoveKind::Rapid);
  EXPECT_EQ(fitted.warnings, path.warnings);
  EXPECT_EQ(fitted.instrument, "T1");
}

// Options that cannot work are refused.
TEST(ArcFit, ImpossibleOptionsAreRefused) {
  ArcFitOptions o;
  o.chord_tolerance = 0;
  EXPECT_THROW(fit_arcs({}, {}, o), std::invalid_argument);
  o = {};
  o.max_sweep_deg = 360;
  EXPECT_THROW(fit_arcs({}, {}, o), std::invalid_argument);
  o = {};
  o.min_chords = 1;
  EXPECT_THROW(fit_arcs({}, {}, o), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------
// Through the post-processor: the arcs as a controller reads them back.

// Posted in both dialects and read back by the interpreter (the post runs it over every
// line, with LinuxCNC's radius check), the arcs' centres are ours within 0.0001 mm and
// their start and end radii agree within 0.0003 mm, on arcs whose points are not on
// the 0.0001 mm grid.
TEST(ArcFit, PostedArcsKeepTheirCentreAndRadiusToTheProgramsFourDecimals) {
  const config::Machine machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
  const config::CuttingTool& tool = machine.tools.front();
  ActionProgram action;
  action.action = 1;
  action.primitive = "P1";
  action.additive = false;
  Toolpath& path = action.path;
  path.process = Process::Milling;
  path.instrument = tool.name;
  path.tool_number = tool.number;
  path.setup = machine.setups.front().name;
  path.start = {10.123456, 20.654321, 30};
  path.safe_z = 30;
  path.moves.push_back(feed_to(10.123456, 20.654321, 10.3, 300));
  for (double r : {0.61234, 3.33333, 17.77777}) {
    const double cx = 10.123456 - r, cy = 20.654321;
    for (const PathMove& m : circle_chords(cx, cy, r, 10.3, 0, 1.9 * kPi, 1000)) path.moves.push_back(m);
    path.moves.push_back(feed_to(10.123456, 20.654321, 10.3));
  }
  path = fit_arcs(path);
  ASSERT_EQ(count(path.moves, MoveKind::ArcCcw), 6) << "each near-full circle: two arcs";
  for (const config::Dialect dialect : {config::Dialect::Rs274ngc, config::Dialect::Fanuc}) {
    gcode::PostOptions options;
    options.dialect = dialect;
    const gcode::PostedProgram program = gcode::post_action(action, machine, options);  // throws on a refused line
    gcode::Interpreter interpreter(machine, "arcs");
    int arcs = 0;
    for (std::size_t i = 0; i < program.lines.size(); ++i) {
      const gcode::LineResult& r = interpreter.execute_line(program.lines[i], int(i + 1));
      for (const gcode::Motion& m : r.motions) {
        if (!m.is_arc()) continue;
        ++arcs;
        const PathMove& ours = path.moves.at(*program.origins[i].move);
        EXPECT_NEAR(m.centre_work.x, ours.centre.x, 1e-4);
        EXPECT_NEAR(m.centre_work.y, ours.centre.y, 1e-4);
        const double r0 = std::hypot(m.from_work.x - m.centre_work.x, m.from_work.y - m.centre_work.y);
        const double r1 = std::hypot(m.to_work.x - m.centre_work.x, m.to_work.y - m.centre_work.y);
        EXPECT_LE(std::abs(r0 - r1), 3e-4) << program.lines[i];
      }
    }
    EXPECT_EQ(arcs, 6) << config::to_string(dialect);
  }
}

}  // namespace
