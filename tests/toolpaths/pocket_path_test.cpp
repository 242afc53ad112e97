// Pocket milling, as a specification. The checks replay the moves against independent
// oracles (toolpath_oracles.hpp): the tool is the planner's continuous body of revolution
// (planner::tool_instrument: cutter, shank, holder), followed at 1/8-voxel steps.
//   - never gouge: no position of any feed move (cuts, links, ramps, plunges) or rapid
//     puts any part of the tool into a voxel of `keep`;
//   - rapids never meet material still there (replayed removal);
//   - plunges only in air; elsewhere ramps no steeper than the ramp angle;
//   - the pocket is cleared: the cutter swept along the moves covers every ROI voxel
//     some allowed tool position could reach (the round tool's corners stay);
//   - levels include every floor; disconnected islands are joined by retracts.

#include "toolpaths/pocket_path.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <set>

#include "toolpaths/setup_frame.hpp"
#include "geometry/mesh.hpp"
#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"
#include "geometry/voxelize.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "toolpath_oracles.hpp"

namespace hybridctl::toolpaths {
namespace {

using geometry::Box3;
using geometry::Index3;
using geometry::IndexBox;
using geometry::Lattice;
using geometry::make_box;
using geometry::Solid;
using geometry::Vec3;
using testing::along;
using testing::Columns;
using testing::move_starts;
using testing::ToolProfile;

const Lattice kLattice{0.5, {0, 0, 0}};

config::CuttingTool flat_4mm() {
  config::CuttingTool t;
  t.number = 7;
  t.name = "4 mm flat";
  t.type = config::ToolType::Flat;
  t.diameter = 4;
  t.flute_length = 8;
  t.shank = {4, 8};
  t.holder = {12, 20};
  t.feed = 900;
  t.plunge_feed = 250;
  t.step_down = 2;
  t.step_over = 1.5;
  return t;
}

config::Setup top_setup() {
  config::Setup s;
  s.name = "top";
  s.approach = config::Approach::PlusZ;
  return s;
}

Solid box(Box3 b) { return make_box(kLattice, b); }

struct Replay {
  int feed_moves = 0, gouges = 0, rapids_into_material = 0, plunges = 0, plunges_into_material = 0, ramps = 0;
  double steepest_ramp_deg = 0;
  Solid present;  // what is left after the moves
};

// Replays the moves in order on `stock`: the cutter removes what it sweeps along feed
// moves; rapids and plunges are checked against what is there at that moment, every
// position against `keep`. Everything in the work frame.
Replay replay(const Toolpath& p, const Solid& stock, const Solid& keep, const config::CuttingTool& tool) {
  const auto instrument = planner::tool_instrument(tool, config::Approach::PlusZ);
  std::vector<geometry::StructuringElement> whole = instrument.cutting;
  whole.insert(whole.end(), instrument.body.begin(), instrument.body.end());
  const ToolProfile tool_all = ToolProfile::from(whole), cutter = ToolProfile::from(instrument.cutting);
  const Columns keep_columns(keep);
  testing::Stock material(stock, cutter);
  Replay r;
  const double h = kLattice.voxel_size;
  const auto starts = move_starts(p);
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    const Vec3 a = starts[i], b = m.to;
    along(a, b, h / 8, [&](Vec3 q) {
      Index3 where;
      if (testing::tool_touches(tool_all, keep_columns, q, &where) && ++r.gouges <= 5)
        ADD_FAILURE() << "move " << i << (m.kind == MoveKind::Rapid ? " (rapid)" : " (feed)") << " at (" << q.x << ", "
                      << q.y << ", " << q.z << ") touches keep voxel (" << where.x << ", " << where.y << ", " << where.z
                      << ")";
    });
    const bool vertical_down = a.x == b.x && a.y == b.y && b.z < a.z;
    if (m.kind == MoveKind::Rapid || (m.kind == MoveKind::Feed && vertical_down)) {
      // Rapids and plunges must meet nothing at all.
      const Columns now(material.present());
      bool hit = false;
      along(a, b, h / 8, [&](Vec3 q) { hit = hit || testing::tool_touches(tool_all, now, q); });
      if (m.kind == MoveKind::Rapid && hit && ++r.rapids_into_material <= 5)
        ADD_FAILURE() << "rapid " << i << " to (" << b.x << ", " << b.y << ", " << b.z << ") meets material";
      if (m.kind == MoveKind::Feed) {
        ++r.plunges;
        if (hit) ++r.plunges_into_material;
      }
    }
    if (m.kind == MoveKind::Feed) {
      ++r.feed_moves;
      EXPECT_GT(m.feed, 0);
      const double run = std::hypot(b.x - a.x, b.y - a.y);
      if (b.z < a.z - 1e-9 && run > 1e-9) {
        ++r.ramps;
        r.steepest_ramp_deg = std::max(r.steepest_ramp_deg, std::atan((a.z - b.z) / run) * 180 / M_PI);
        EXPECT_DOUBLE_EQ(m.feed, tool.plunge_feed) << "ramps at the plunge feed";
      }
      material.cut_along(a, b);
    }
  }
  r.present = material.present();
  return r;
}

// The ROI voxels some allowed tool position reaches, by morphology on the planner's
// exact instrument: tips where the whole tool misses `keep`, grown by the cutter.
Solid reachable(const Solid& roi, const Solid& keep, const config::CuttingTool& tool) {
  const auto instrument = planner::tool_instrument(tool, config::Approach::PlusZ);
  IndexBox domain = roi.bounding_box();
  const int m = int(std::ceil(tool.diameter / kLattice.voxel_size)) + 2;
  domain = {{domain.lo.x - m, domain.lo.y - m, domain.lo.z}, {domain.hi.x + m, domain.hi.y + m, domain.hi.z + 40}};
  Solid forbidden(kLattice, domain);
  for (const auto& e : instrument.cutting) forbidden = geometry::unite(forbidden, geometry::dilate(keep, geometry::reflected(e), domain));
  for (const auto& e : instrument.body) forbidden = geometry::unite(forbidden, geometry::dilate(keep, geometry::reflected(e), domain));
  const Solid allowed = geometry::complement(forbidden, domain);
  Solid swept(kLattice, domain);
  for (const auto& e : instrument.cutting) swept = geometry::unite(swept, geometry::dilate(allowed, e, domain));
  return geometry::intersect(roi, swept);
}

std::set<long> feed_levels(const Toolpath& p) {
  std::set<long> z;
  const auto starts = move_starts(p);
  for (std::size_t i = 0; i < p.moves.size(); ++i)
    if (p.moves[i].kind == MoveKind::Feed && starts[i].z == p.moves[i].to.z) z.insert(std::lround(p.moves[i].to.z * 1000));
  return z;
}

double centre_z(int k) { return kLattice.origin.z + (k + 0.5) * kLattice.voxel_size; }

// A block with a closed rectangular pocket, 16 x 14 mm, 5 mm deep.
struct ClosedPocket {
  Solid stock = box({{0, 0, 0}, {24, 22, 8}});
  Solid roi = box({{4, 4, 3}, {20, 18, 8}});
  Solid keep = geometry::subtract(stock, roi);
};

TEST(PocketPath, RecordsTheToolSetupAndSafeHeight) {
  const ClosedPocket c;
  const Toolpath p = pocket_path(c.roi, c.keep, c.stock, flat_4mm(), top_setup());
  EXPECT_EQ(p.process, Process::Milling);
  EXPECT_EQ(p.instrument, "4 mm flat");
  EXPECT_EQ(p.tool_number, 7);
  EXPECT_EQ(p.setup, "top");
  EXPECT_GE(p.safe_z, 8 + 1e-9) << "above all material";
  ASSERT_FALSE(p.moves.empty());
  EXPECT_EQ(p.moves.front().kind, MoveKind::Rapid);
  EXPECT_EQ(p.moves.front().to, p.start);
  EXPECT_DOUBLE_EQ(p.start.z, p.safe_z);
  EXPECT_DOUBLE_EQ(p.moves.back().to.z, p.safe_z);
  for (const auto& m : p.moves) {
    EXPECT_LE(m.to.z, p.safe_z + 1e-9);
    if (m.kind == MoveKind::Rapid) {
      EXPECT_EQ(m.feed, 0);
    } else {
      EXPECT_TRUE(m.feed == 900 || m.feed == 250) << m.feed;
    }
  }
}

TEST(PocketPath, ClosedPocketIsClearedWithoutGougingAndEnteredByRamps) {
  const ClosedPocket c;
  const auto tool = flat_4mm();
  const auto t0 = std::chrono::steady_clock::now();
  const Toolpath p = pocket_path(c.roi, c.keep, c.stock, tool, top_setup());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  const Replay r = replay(p, c.stock, c.keep, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(r.rapids_into_material, 0);
  EXPECT_EQ(r.plunges_into_material, 0) << "a closed pocket is entered by ramping, never by plunging into material";
  EXPECT_GT(r.ramps, 0);
  EXPECT_LE(r.steepest_ramp_deg, 3.0 + 1e-6);
  // Cleared: what stays of the ROI is only what no allowed tool position reaches (the
  // four vertical corners a round tool leaves).
  const Solid left = geometry::intersect(r.present, c.roi);
  const Solid unreachable = geometry::subtract(c.roi, reachable(c.roi, c.keep, tool));
  EXPECT_EQ(geometry::subtract(left, unreachable).voxel_count(), 0) << "reachable ROI left uncut";
  EXPECT_GT(unreachable.voxel_count(), 0);
  // A 2 mm radius in a corner leaves the 8 voxels of each layer (0.5 mm) whose centres
  // are farther than 2 mm from every allowed tip: 4 corners x 10 layers x 8.
  EXPECT_EQ(unreachable.voxel_count(), 4 * 10 * 8) << "only the corners are out of reach";
  // The floor is cut at the ROI's bottom voxel layer.
  EXPECT_TRUE(feed_levels(p).count(std::lround(centre_z(6) * 1000)));
}

TEST(PocketPath, ZigzagRowsAreAtMostAStepOverApart) {
  const Solid stock = box({{0, 0, 0}, {30, 30, 4}});
  const Solid roi = box({{3, 3, 2}, {27, 27, 4}});
  const Solid keep = geometry::subtract(stock, roi);
  const auto tool = flat_4mm();
  PocketOptions o;
  o.wall_pass = WallPass::None;
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup(), o);
  const auto starts = move_starts(p);
  std::set<long> rows;  // y (um) of cuts along X
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    if (m.kind == MoveKind::Feed && m.process_on && m.to.z == starts[i].z && m.to.y == starts[i].y &&
        std::abs(m.to.x - starts[i].x) > tool.diameter)
      rows.insert(std::lround(m.to.y * 1000));
  }
  ASSERT_GE(rows.size(), 8u);
  // From the first row at the edge of the tool's reach (2 mm off the wall, on a voxel
  // centre) to the last, no two neighbours more than step_over apart.
  EXPECT_EQ(*rows.begin(), 5250);
  EXPECT_EQ(*rows.rbegin(), 24750);
  for (auto it = std::next(rows.begin()); it != rows.end(); ++it)
    EXPECT_LE(*it - *std::prev(it), std::lround(tool.step_over * 1000)) << "rows at " << *std::prev(it) << " and " << *it;
  // Rows alone clear the floor away from the walls.
  const Replay r = replay(p, stock, keep, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(geometry::intersect(r.present, box({{5, 5, 2}, {25, 25, 4}})).voxel_count(), 0);
}

TEST(PocketPath, OpenPocketsArePlungedInAirAndLedIn) {
  // A slot through the block's +X side: the tool can start outside the stock.
  const Solid stock = box({{0, 0, 0}, {20, 16, 8}});
  const Solid roi = box({{6, 5, 4}, {20, 11, 8}});
  const Solid keep = geometry::subtract(stock, roi);
  const auto tool = flat_4mm();
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup());
  const Replay r = replay(p, stock, keep, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(r.rapids_into_material, 0);
  EXPECT_EQ(r.plunges_into_material, 0);
  EXPECT_GT(r.plunges, 0);
  EXPECT_EQ(r.ramps, 0) << "every level can be entered from the open side";
  const Solid left = geometry::intersect(r.present, roi);
  EXPECT_EQ(geometry::subtract(left, geometry::subtract(roi, reachable(roi, keep, tool))).voxel_count(), 0);
}

TEST(PocketPath, LevelsIncludeEveryFloor) {
  // A stepped pocket: floors at 5.0 mm and 2.5 mm, neither a multiple of the 2 mm step
  // down from the top at 8 mm.
  const Solid stock = box({{0, 0, 0}, {20, 16, 8}});
  const Solid roi = geometry::unite(box({{3, 3, 5}, {17, 13, 8}}), box({{6, 5, 2.5}, {12, 11, 5}}));
  const Solid keep = geometry::subtract(stock, roi);
  const auto tool = flat_4mm();
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup());
  const auto levels = feed_levels(p);
  EXPECT_TRUE(levels.count(std::lround(centre_z(10) * 1000))) << "the upper floor (voxel layer 10)";
  EXPECT_TRUE(levels.count(std::lround(centre_z(5) * 1000))) << "the lower floor (voxel layer 5)";
  // No level cuts deeper than a step below the one before it.
  long previous = std::lround(8000);
  for (auto it = levels.rbegin(); it != levels.rend(); ++it) {
    EXPECT_LE(previous - *it, 2000 + 1);
    previous = *it;
  }
  const Replay r = replay(p, stock, keep, tool);
  EXPECT_EQ(r.gouges, 0);
  const Solid left = geometry::intersect(r.present, roi);
  EXPECT_EQ(geometry::subtract(left, geometry::subtract(roi, reachable(roi, keep, tool))).voxel_count(), 0);
}

TEST(PocketPath, DisconnectedIslandsAreJoinedByRetracts) {
  // Two pockets with a wall between them: no feed move may cross the wall.
  const Solid stock = box({{0, 0, 0}, {30, 14, 6}});
  const Solid roi = geometry::unite(box({{3, 3, 3}, {12, 11, 6}}), box({{18, 3, 3}, {27, 11, 6}}));
  const Solid keep = geometry::subtract(stock, roi);
  const auto tool = flat_4mm();
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup());
  const auto starts = move_starts(p);
  int crossings = 0, retracts = 0;
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    const auto& m = p.moves[i];
    const bool left_a = starts[i].x < 15, left_b = m.to.x < 15;
    if (left_a != left_b) {
      ++crossings;
      EXPECT_EQ(m.kind, MoveKind::Rapid) << "move " << i << " crosses the wall";
      EXPECT_DOUBLE_EQ(m.to.z, p.safe_z);
      EXPECT_DOUBLE_EQ(starts[i].z, p.safe_z);
    }
    if (m.kind == MoveKind::Rapid && m.to.z == p.safe_z && starts[i].z < p.safe_z) ++retracts;
  }
  EXPECT_GE(crossings, 1);
  EXPECT_GE(retracts, 2);
  const Replay r = replay(p, stock, keep, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(r.plunges_into_material, 0);
  const Solid left = geometry::intersect(r.present, roi);
  EXPECT_EQ(geometry::subtract(left, geometry::subtract(roi, reachable(roi, keep, tool))).voxel_count(), 0);
}

// A pocket around a round boss, with a ball, a bull and a flat tool whose shank is
// narrower than its cutter: curved walls, tools that are not flat, retracts that sweep.
TEST(PocketPath, NoToolEverTouchesWhatMustRemain) {
  const Solid stock = box({{0, 0, 0}, {22, 22, 7}});
  const Solid boss = geometry::make_cylinder(kLattice, geometry::Axis::Z, {11, 11, 0}, 3.2, 7);
  const Solid roi = geometry::subtract(box({{2.5, 2.5, 2}, {19.5, 19.5, 7}}), boss);
  const Solid keep = geometry::subtract(stock, roi);
  config::CuttingTool ball = flat_4mm();
  ball.type = config::ToolType::Ball;
  ball.corner_radius = 2;
  config::CuttingTool bull = flat_4mm();
  bull.type = config::ToolType::Bull;
  bull.corner_radius = 0.75;
  config::CuttingTool necked = flat_4mm();
  necked.shank = {3, 6};
  for (const auto& tool : {flat_4mm(), ball, bull, necked}) {
    SCOPED_TRACE(std::string(config::to_string(tool.type)) + " shank " + std::to_string(tool.shank.diameter));
    const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup());
    const Replay r = replay(p, stock, keep, tool);
    EXPECT_GT(r.feed_moves, 20);
    EXPECT_EQ(r.gouges, 0);
    EXPECT_EQ(r.rapids_into_material, 0);
    EXPECT_EQ(r.plunges_into_material, 0);
    EXPECT_LE(r.steepest_ramp_deg, 3.0 + 1e-6);
  }
}

TEST(PocketPath, ContourParallelRingsClearToo) {
  const Solid stock = box({{0, 0, 0}, {22, 22, 6}});
  const Solid boss = geometry::make_cylinder(kLattice, geometry::Axis::Z, {11, 11, 0}, 3, 6);
  const Solid roi = geometry::subtract(box({{2.5, 2.5, 3}, {19.5, 19.5, 6}}), boss);
  const Solid keep = geometry::subtract(stock, roi);
  const auto tool = flat_4mm();
  PocketOptions o;
  o.strategy = PocketStrategy::Offsets;
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup(), o);
  const Replay r = replay(p, stock, keep, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(r.plunges_into_material, 0);
  const Solid left = geometry::intersect(r.present, roi);
  EXPECT_EQ(geometry::subtract(left, geometry::subtract(roi, reachable(roi, keep, tool))).voxel_count(), 0);
}

TEST(PocketPath, RowsAlongYAndAlternatingRowsClearToo) {
  const ClosedPocket c;
  const auto tool = flat_4mm();
  for (PocketRaster raster : {PocketRaster::AlongY, PocketRaster::Alternate}) {
    PocketOptions o;
    o.raster = raster;
    const Toolpath p = pocket_path(c.roi, c.keep, c.stock, tool, top_setup(), o);
    const Replay r = replay(p, c.stock, c.keep, tool);
    EXPECT_EQ(r.gouges, 0);
    const Solid left = geometry::intersect(r.present, c.roi);
    EXPECT_EQ(geometry::subtract(left, geometry::subtract(c.roi, reachable(c.roi, c.keep, tool))).voxel_count(), 0);
  }
}

TEST(PocketPath, TheHolderKeepsTheToolOutOfDeepNarrowPlaces) {
  // A deep pocket next to a tall wall: the 12 mm holder, 16 mm above the tip, must not
  // hit the wall when the tip goes down next to it.
  const Solid stock = box({{0, 0, 0}, {24, 16, 4}});
  const Solid tower = box({{0, 0, 0}, {6, 16, 24}});
  const Solid roi = box({{7, 3, 1}, {21, 13, 4}});
  const Solid keep = geometry::unite(geometry::subtract(stock, roi), tower);
  const auto tool = flat_4mm();
  const Toolpath p = pocket_path(roi, keep, geometry::unite(stock, tower), tool, top_setup());
  const Replay r = replay(p, geometry::unite(stock, tower), keep, tool);
  EXPECT_GT(r.feed_moves, 10);
  EXPECT_EQ(r.gouges, 0);
  // Within the holder's radius of the tower the ROI stays; the warning says so.
  bool warned = false;
  for (const auto& w : p.warnings) warned = warned || w.find("cannot reach") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_GT(geometry::intersect(r.present, roi).voxel_count(), 0);
}

TEST(PocketPath, OtherSetupsMillInTheirWorkFrame) {
  // A pocket in the block's +X face, milled from +X.
  const Solid stock = box({{0, 0, 0}, {10, 16, 14}});
  const Solid roi = box({{6, 4, 3}, {10, 12, 11}});
  const Solid keep = geometry::subtract(stock, roi);
  config::Setup side;
  side.name = "side";
  side.approach = config::Approach::PlusX;
  const auto tool = flat_4mm();
  const Toolpath p = pocket_path(roi, keep, stock, tool, side);
  EXPECT_EQ(p.setup, "side");
  const Solid stock_w = part_to_work(stock, side.approach), keep_w = part_to_work(keep, side.approach),
              roi_w = part_to_work(roi, side.approach);
  const Replay r = replay(p, stock_w, keep_w, tool);
  EXPECT_EQ(r.gouges, 0);
  EXPECT_EQ(r.plunges_into_material, 0);
  const Solid left = geometry::intersect(r.present, roi_w);
  EXPECT_EQ(geometry::subtract(left, geometry::subtract(roi_w, reachable(roi_w, keep_w, tool))).voxel_count(), 0);
  // In the part frame the cutting happens inside the pocket, tool axis along +X.
  for (const auto& m : p.moves)
    if (m.kind == MoveKind::Feed && m.process_on) {
      EXPECT_GE(work_to_part(m.to, side.approach).x, 6 - 1e-9);
    }
}

// Closed meshes for wall finishing (a flat cutter on the design's real walls).
using geometry::Triangle;

void add_quad(std::vector<Triangle>& m, Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  m.push_back({a, b, c});
  m.push_back({a, c, d});
}

// A block with a rectangular pocket open at its top (pocket.max.z == outer.max.z).
std::vector<Triangle> pocketed_block(Box3 o, Box3 p) {
  std::vector<Triangle> m;
  const double z0 = o.min.z, z1 = o.max.z, zf = p.min.z;
  const Vec3 oc[4] = {{o.min.x, o.min.y, 0}, {o.max.x, o.min.y, 0}, {o.max.x, o.max.y, 0}, {o.min.x, o.max.y, 0}};
  const Vec3 pc[4] = {{p.min.x, p.min.y, 0}, {p.max.x, p.min.y, 0}, {p.max.x, p.max.y, 0}, {p.min.x, p.max.y, 0}};
  auto at = [](Vec3 v, double z) { return Vec3{v.x, v.y, z}; };
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    add_quad(m, at(oc[i], z0), at(oc[j], z0), at(oc[j], z1), at(oc[i], z1));  // outer sides
    add_quad(m, at(pc[j], zf), at(pc[i], zf), at(pc[i], z1), at(pc[j], z1));  // pocket walls
    add_quad(m, at(oc[i], z1), at(oc[j], z1), at(pc[j], z1), at(pc[i], z1));  // top, round the pocket
  }
  add_quad(m, at(oc[0], z0), at(oc[3], z0), at(oc[2], z0), at(oc[1], z0));  // bottom
  add_quad(m, at(pc[0], zf), at(pc[1], zf), at(pc[2], zf), at(pc[3], zf));  // pocket floor
  return m;
}

// A prism over a convex polygon, z0..z1.
std::vector<Triangle> prism_mesh(const std::vector<Vec3>& poly, double z0, double z1) {
  std::vector<Triangle> m;
  const std::size_t n = poly.size();
  auto at = [](Vec3 v, double z) { return Vec3{v.x, v.y, z}; };
  for (std::size_t i = 0; i < n; ++i) add_quad(m, at(poly[i], z0), at(poly[(i + 1) % n], z0), at(poly[(i + 1) % n], z1), at(poly[i], z1));
  for (std::size_t i = 1; i + 1 < n; ++i) {
    m.push_back({at(poly[0], z0), at(poly[i + 1], z0), at(poly[i], z0)});
    m.push_back({at(poly[0], z1), at(poly[i], z1), at(poly[i + 1], z1)});
  }
  return m;
}

std::vector<Vec3> rectangle_xy(Box3 b) { return {{b.min.x, b.min.y, 0}, {b.max.x, b.min.y, 0}, {b.max.x, b.max.y, 0}, {b.min.x, b.max.y, 0}}; }

double distance_to_polygon(double x, double y, const std::vector<Vec3>& poly) {
  bool in = false;
  double d = 1e300;
  for (std::size_t i = 0, n = poly.size(); i < n; ++i) {
    const Vec3 a = poly[i], b = poly[(i + 1) % n];
    if ((a.y > y) != (b.y > y) && a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x) > x) in = !in;
    const double dx = b.x - a.x, dy = b.y - a.y, l2 = dx * dx + dy * dy;
    const double t = std::clamp(((x - a.x) * dx + (y - a.y) * dy) / l2, 0.0, 1.0);
    d = std::min(d, std::hypot(x - a.x - t * dx, y - a.y - t * dy));
  }
  return in ? -d : d;
}

// The closest any tool position of the path comes to a wall (signed distance of the tip
// from `wall` in XY, negative inside), over the positions whose cutter reaches heights in
// (z_lo, z_hi): followed every 1/8 voxel. With `feeds_only`, only along cutting moves.
double closest_approach(const Toolpath& p, const std::function<double(double, double)>& wall, double z_lo, double z_hi,
                        bool feeds_only = false) {
  double best = 1e300;
  const auto starts = move_starts(p);
  for (std::size_t i = 0; i < p.moves.size(); ++i) {
    if (feeds_only && !(p.moves[i].kind == MoveKind::Feed && p.moves[i].process_on)) continue;
    along(starts[i], p.moves[i].to, kLattice.voxel_size / 8, [&](Vec3 q) {
      if (q.z < z_hi - 1e-9 && q.z > z_lo - 1e-9) best = std::min(best, wall(q.x, q.y));
    });
  }
  return best;
}

// The tip polylines of the wall finishing passes: from each lead-in to its lead-out.
std::vector<std::vector<Vec3>> finishing_passes(const Toolpath& p) {
  std::vector<std::vector<Vec3>> out;
  bool in = false;
  for (const auto& m : p.moves) {
    if (m.comment.find("finish lead-in") != std::string::npos) {
      out.emplace_back();
      in = true;
    } else if (m.comment.find("finish lead-out") != std::string::npos && in) {
      in = false;
      continue;
    }
    if (in) out.back().push_back(m.to);
  }
  return out;
}

TEST(PocketPath, WallFinishingPutsAFlatCuttersSideOnThePocketsRealWalls) {
  // Walls between voxel centres: the lattice alone keeps the cutter up to a voxel off them.
  const Box3 outer{{0, 0, 0}, {24, 22, 8}}, hole{{4.2, 4.1, 3}, {19.9, 17.8, 8}};
  const auto mesh = std::make_shared<const std::vector<Triangle>>(pocketed_block(outer, hole));
  const Solid stock = box(outer);
  const Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "pocketed block");
  const Solid roi = geometry::subtract(stock, design);
  auto tool = flat_4mm();
  tool.finish_feed = tool.feed / 2;
  tool.finish_spindle_speed = tool.spindle_speed * 1.5;
  const double r = tool.diameter / 2;
  PocketOptions on;
  on.design = mesh;
  on.design_voxels = &design;
  PocketOptions off = on;
  off.finish_walls = false;
  const Toolpath p = pocket_path(roi, design, stock, tool, top_setup(), on);
  const Toolpath q = pocket_path(roi, design, stock, tool, top_setup(), off);
  for (const auto& w : p.warnings) EXPECT_EQ(w.find("wall finishing"), std::string::npos) << w;
  const Replay rp = replay(p, stock, design, tool);
  EXPECT_EQ(rp.gouges, 0);
  EXPECT_EQ(rp.rapids_into_material, 0);
  EXPECT_EQ(rp.plunges_into_material, 0);
  // Below the block's top, no tool position ever has its cutter in the STL's solid (any
  // move, roughing included), and the finishing passes put it on each wall within the
  // chord tolerance (0.001) and the clearance (0.0002).
  const std::vector<Vec3> pocket_xy = rectangle_xy(hole);
  auto inside_pocket = [&](double x, double y) { return -distance_to_polygon(x, y, pocket_xy); };
  EXPECT_GE(closest_approach(p, inside_pocket, 3, 8), r + 0.0002 - 1e-9);
  for (const auto& [name, wall] : std::vector<std::pair<std::string, std::function<double(double, double)>>>{
           {"x = 4.2", [](double x, double) { return x - 4.2; }},
           {"x = 19.9", [](double x, double) { return 19.9 - x; }},
           {"y = 4.1", [](double, double y) { return y - 4.1; }},
           {"y = 17.8", [](double, double y) { return 17.8 - y; }}}) {
    SCOPED_TRACE(name);
    EXPECT_LE(closest_approach(p, wall, 3, 8, true), r + 0.0012 + 1e-9);
  }
  // Without the finishing, the lattice stays 0.15 mm off the wall at x = 19.9 (the nearest
  // allowed tip is on the voxel centre 17.75).
  EXPECT_NEAR(closest_approach(q, [](double x, double) { return 19.9 - x; }, 3, 8, true), r + 0.15, 1e-9);
  // Climb milling inside a pocket: its passes run counter-clockwise.
  const auto passes = finishing_passes(p);
  ASSERT_FALSE(passes.empty());
  for (const auto& pass : passes) {
    double area = 0;
    for (std::size_t i = 0; i + 1 < pass.size(); ++i) area += pass[i].x * pass[i + 1].y - pass[i + 1].x * pass[i].y;
    EXPECT_GT(area, 0);
  }
  // Each pass comes onto the wall along a quarter circle tangent to it: the lead-in's last
  // chord turns into the wall's direction by at most half a chord's angle (a straight lead
  // meets it at 45 or 90 degrees).
  int arc_leads = 0;
  bool arc = false;
  for (std::size_t i = 1; i + 1 < p.moves.size(); ++i) {
    if (p.moves[i].comment == "finish lead-in arc") arc = true;
    if (p.moves[i].comment != "finish lead-in") continue;
    EXPECT_EQ(p.moves[i].feed, tool.finish_feed) << "the finishing passes run at the tool's finishing feed";
    EXPECT_EQ(p.moves[i].spindle, tool.finish_spindle_speed) << "... and spindle speed";
    if (arc) {
      ++arc_leads;
      const Vec3 a = p.moves[i - 1].to, b = p.moves[i].to, c = p.moves[i + 1].to;
      const double turn = std::abs(std::atan2((b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x),
                                              (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y)));
      EXPECT_LT(turn * 180 / M_PI, 3.0) << "at (" << b.x << ", " << b.y << ")";
    }
    arc = false;
  }
  EXPECT_GT(arc_leads, 0);
  // The roughing's feed moves keep the tool's own spindle speed.
  EXPECT_TRUE(std::any_of(p.moves.begin(), p.moves.end(), [&](const PathMove& m) {
    return m.kind == MoveKind::Feed && m.feed == tool.feed && m.spindle == 0;
  }));
  // What stays of the ROI on the voxels is no more than without the finishing.
  const Replay rq = replay(q, stock, design, tool);
  EXPECT_LE(geometry::intersect(rp.present, roi).voxel_count(), geometry::intersect(rq.present, roi).voxel_count());
}

TEST(PocketPath, WallFinishingKeepsOffWhatStaysThatIsNotDesign) {
  // A 48-gon boss of radius 4.1 on a 2 mm base; east of it a rib of stock kept for a later
  // action (not design): the pass round the boss must leave it, and still finish the rest.
  std::vector<Vec3> gon;
  for (int i = 0; i < 48; ++i)
    gon.push_back({11 + 4.1 * std::cos(2 * M_PI * i / 48), 11 + 4.1 * std::sin(2 * M_PI * i / 48), 0});
  auto parts = prism_mesh(rectangle_xy({{0, 0, 0}, {22, 22, 2}}), 0, 2);
  const auto boss = prism_mesh(gon, 2, 7);
  parts.insert(parts.end(), boss.begin(), boss.end());
  const auto mesh = std::make_shared<const std::vector<Triangle>>(parts);
  const Solid stock = box({{0, 0, 0}, {22, 22, 7}});
  const Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "boss");
  const Solid rib = box({{14.5, 9, 2}, {22, 13, 7}});
  const Solid keep = geometry::unite(design, rib);
  const Solid roi = geometry::subtract(stock, keep);
  const auto tool = flat_4mm();
  const double r = tool.diameter / 2;
  PocketOptions o;
  o.design = mesh;  // the design's voxels made from it
  const Toolpath p = pocket_path(roi, keep, stock, tool, top_setup(), o);
  const Replay rp = replay(p, stock, keep, tool);
  EXPECT_EQ(rp.gouges, 0) << "the rib is kept";
  EXPECT_EQ(rp.rapids_into_material, 0);
  EXPECT_EQ(rp.plunges_into_material, 0);
  auto off_boss = [&](double x, double y) { return distance_to_polygon(x, y, gon); };
  EXPECT_GE(closest_approach(p, off_boss, 2, 7), r + 0.0002 - 1e-9);
  EXPECT_LE(closest_approach(p, off_boss, 2, 7, true), r + 0.0012 + 1e-9);
  // Finishing passes run clockwise round the island and stay off the rib's side of it.
  const auto passes = finishing_passes(p);
  ASSERT_FALSE(passes.empty());
  for (const auto& pass : passes) {
    double area = 0;
    for (std::size_t i = 0; i + 1 < pass.size(); ++i) area += pass[i].x * pass[i + 1].y - pass[i + 1].x * pass[i].y;
    EXPECT_LT(area, 0);
  }
}

// A block standing off the lattice (its walls between voxel centres), with all round it
// the region a removal may take, and the options that finish its walls from the STL.
struct BlockInAir {
  Box3 block{{6.2, 6.1, 0}, {15.9, 15.8, 8}};
  std::shared_ptr<const std::vector<Triangle>> mesh =
      std::make_shared<const std::vector<Triangle>>(prism_mesh(rectangle_xy(block), 0, 8));
  Solid design = geometry::voxelize(geometry::TriangleMesh{*mesh}, kLattice, "block");
  Solid region = geometry::subtract(box({{0, 0, 0}, {22, 22, 10}}), design);
  PocketOptions finishing() const {
    PocketOptions o;
    o.design = mesh;
    o.design_voxels = &design;
    o.finish_region = &region;
    return o;
  }
  // Signed distance from the block's outline in XY (negative inside).
  double off_block(double x, double y) const { return distance_to_polygon(x, y, rectangle_xy(block)); }
};

TEST(PocketPath, WallFinishingRunsOnUnderTheLowestLevelWhereABeadsSpillMayStand) {
  // A deposit's overfill round the top of a block: its voxels start at z = 5, its beads
  // (laid at their own layer heights) may reach lower. The region the action may remove is
  // all round the block, so its walls are finished on down a material allowance (1 mm)
  // under the lowest level, and no lower.
  const BlockInAir b;
  const Solid overfill = geometry::subtract(box({{4, 4, 5}, {18, 18, 8}}), b.design);
  const Solid stock = geometry::unite(b.design, overfill);
  const auto tool = flat_4mm();
  const double r = tool.diameter / 2;
  const Toolpath p = pocket_path(overfill, b.design, stock, tool, top_setup(), b.finishing());
  const Replay rp = replay(p, stock, b.design, tool);
  EXPECT_EQ(rp.gouges, 0);
  EXPECT_EQ(rp.rapids_into_material, 0);
  EXPECT_EQ(rp.plunges_into_material, 0);
  double lowest = 1e300;
  for (const auto& pass : finishing_passes(p))
    for (const Vec3& q : pass) lowest = std::min(lowest, q.z);
  // The lowest level is the overfill's bottom layer (tip at its centre, 5.25): passes at
  // the centres of the two layers under it, 4.75 and 4.25.
  EXPECT_NEAR(lowest, 4.25, 1e-9);
  auto off_block = [&](double x, double y) { return b.off_block(x, y); };
  EXPECT_GE(closest_approach(p, off_block, 4, 8), r + 0.0002 - 1e-9) << "never into the block";
  EXPECT_LE(closest_approach(p, off_block, 4.2, 4.3, true), r + 0.0012 + 1e-9) << "on its walls down there";
}

TEST(PocketPath, TheWallsADepositLaidAreFinishedWhereNoVoxelIsLeftToRemove) {
  // A block laid near-net from z = 3 up: on the voxels nothing stands outside it, but its
  // beads stand past the STL by up to the head's accuracy. A removal whose region is all
  // round it finishes those walls at every step-down of the laid height, and down a
  // material allowance (1 mm) under it; with nothing laid it has nothing to do.
  const BlockInAir b;
  const Solid laid = geometry::intersect(b.design, box({{0, 0, 3}, {22, 22, 8}}));
  const Solid nothing(kLattice, {});
  const auto tool = flat_4mm();
  const double r = tool.diameter / 2;
  PocketOptions o = b.finishing();
  const Toolpath idle = pocket_path(nothing, b.design, b.design, tool, top_setup(), o);
  EXPECT_TRUE(idle.moves.empty());
  ASSERT_FALSE(idle.warnings.empty());
  EXPECT_NE(idle.warnings.front().find("nothing to remove"), std::string::npos) << idle.warnings.front();
  o.laid = &laid;
  const Toolpath p = pocket_path(nothing, b.design, b.design, tool, top_setup(), o);
  EXPECT_TRUE(p.defects.empty());
  const Replay rp = replay(p, b.design, b.design, tool);
  EXPECT_EQ(rp.gouges, 0);
  EXPECT_EQ(rp.rapids_into_material, 0);
  EXPECT_EQ(rp.plunges_into_material, 0);
  std::set<double> heights;
  for (const auto& pass : finishing_passes(p))
    for (const Vec3& q : pass) heights.insert(q.z);
  ASSERT_FALSE(heights.empty());
  // From the top laid layer's centre (7.75) down, a step-down (the tool's 2 mm) apart at
  // most, to the lowest laid layer's centre (3.25) and the two under it (2.75, 2.25).
  EXPECT_NEAR(*heights.rbegin(), 7.75, 1e-9);
  EXPECT_NEAR(*heights.begin(), 2.25, 1e-9);
  for (auto it = std::next(heights.begin()); it != heights.end(); ++it)
    EXPECT_LE(*it - *std::prev(it), tool.step_down + 1e-9) << "between " << *std::prev(it) << " and " << *it;
  auto off_block = [&](double x, double y) { return b.off_block(x, y); };
  EXPECT_GE(closest_approach(p, off_block, 0, 10), r + 0.0002 - 1e-9) << "never into the block";
  for (const double z : heights)
    EXPECT_LE(closest_approach(p, off_block, z - 0.01, z + 0.01, true), r + 0.0012 + 1e-9) << "on its walls at z = " << z;
  // Given the block's top as a floor the tool faces, the top is skimmed at its height too
  // (a bead's top stands above it): feed moves at z = 8 over the middle of the block.
  for (const Triangle& t : *b.mesh)
    if (t[0].z == 8 && t[1].z == 8 && t[2].z == 8) o.floors.push_back(t);
  ASSERT_FALSE(o.floors.empty());
  const Toolpath skimmed = pocket_path(nothing, b.design, b.design, tool, top_setup(), o);
  const Replay rs = replay(skimmed, b.design, b.design, tool);
  EXPECT_EQ(rs.gouges, 0);
  EXPECT_EQ(rs.plunges_into_material, 0);
  // The deepest a feed move at z = 8 comes inside the block's outline (mm, negative inside).
  const double no_skim = closest_approach(p, off_block, 8 - 1e-6, 8 + 1e-6, true);
  const double skim = closest_approach(skimmed, off_block, 8 - 1e-6, 8 + 1e-6, true);
  EXPECT_GT(no_skim, 0) << "no floor given, no skim";
  EXPECT_LT(skim, -4) << "rows across the top";
}

TEST(PocketPath, NothingToRemoveGivesAnEmptyPathWithAWarning) {
  const Solid stock = box({{0, 0, 0}, {10, 10, 5}});
  const Toolpath p = pocket_path(Solid(kLattice, {}), stock, stock, flat_4mm(), top_setup());
  EXPECT_TRUE(p.moves.empty());
  EXPECT_FALSE(p.warnings.empty());
}

}  // namespace
}  // namespace hybridctl::toolpaths
