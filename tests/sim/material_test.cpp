// The material simulation as a specification: what a cutter removes, what a bead adds,
// and which incidents (rapid into material, body collision, gouge, unsupported or lost
// deposition) a move raises, with its line.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "geometry/shapes.hpp"
#include "sim/material.hpp"
#include "sim_fixtures.hpp"

namespace hybridctl::sim {
namespace {

using namespace testing;
using geometry::Vec3;

// Stock: voxel centres 0..20 mm in X and Y, 0..10 mm in Z.
const IndexBox kStockBox{{0, 0, 0}, {41, 41, 21}};
Solid full_stock() { return Solid::filled(kLattice, kStockBox); }

config::CuttingTool tool(config::ToolType type, double diameter, double flute, config::ToolBody shank,
                         config::ToolBody holder = {30, 40}) {
  config::CuttingTool t;
  t.number = 1;
  t.type = type;
  t.diameter = diameter;
  t.corner_radius = type == config::ToolType::Ball ? diameter / 2 : 0;
  t.flute_length = flute;
  t.shank = shank;
  t.holder = holder;
  return t;
}

MaterialMove feed(Vec3 from, Vec3 to, int line) { return {Motion::Linear, from, to, {}, false, line}; }
MaterialMove rapid(Vec3 from, Vec3 to, int line) { return {Motion::Rapid, from, to, {}, false, line}; }

std::int64_t count_of(const std::vector<Incident>& incidents, IncidentKind kind) {
  std::int64_t n = 0;
  for (const Incident& i : incidents) n += i.kind == kind;
  return n;
}

// The removed voxels.
Solid removed(const Solid& before, const MaterialSimulation& sim) { return geometry::subtract(before, sim.stock()); }

TEST(Instruments, ToolsAndHeadsBecomeTheirShapes) {
  const Cutter ball = cutter_of(tool(config::ToolType::Ball, 6, 18, {6, 12}, {40, 50}));
  ASSERT_EQ(ball.cutting.size(), 2u);
  EXPECT_EQ(ball.cutting[0].kind, Kind::Sphere);
  EXPECT_EQ(ball.cutting[0].centre, 3);  // the tip, not the ball centre, is the programmed point
  EXPECT_EQ(ball.cutting[1].to, 18);
  ASSERT_EQ(ball.body.size(), 2u);
  EXPECT_EQ(ball.body[0].from, 18);
  EXPECT_EQ(ball.body[0].to, 30);
  EXPECT_EQ(ball.body[1].radius, 20);
  EXPECT_TRUE(std::isinf(ball.body[1].to));  // the holder leads into the spindle
  config::CuttingTool bull_tool = tool(config::ToolType::Bull, 10, 30, {10, 20});
  bull_tool.corner_radius = 2;
  const Cutter bull = cutter_of(bull_tool);
  EXPECT_EQ(bull.cutting[0].kind, Kind::Torus);
  EXPECT_EQ(bull.cutting[0].ring, 3);
  config::AdditiveHead head;
  head.bead = {config::BeadShape::Cylinder, 3, 1.2};
  const Bead bead = bead_of(head);
  EXPECT_EQ(bead.shape, config::BeadShape::Cylinder);
  EXPECT_EQ(bead.width, 3);
  EXPECT_EQ(bead.height, 1.2);
}

TEST(MaterialSimulation, APlungeMakesAFlatBottomedCylindricalHole) {
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 4, 8, {4, 8}));
  MaterialSimulation sim(full_stock());
  const MoveReport r = sim.cut(mill, feed({10, 10, 12}, {10, 10, 4}, 5));
  const Solid hole = geometry::make_cylinder(kLattice, geometry::Axis::Z, {10, 10, 4}, 2, 100);
  EXPECT_EQ(sim.stock(), geometry::subtract(full_stock(), hole));
  const std::int64_t n = geometry::intersect(full_stock(), hole).voxel_count();
  EXPECT_GT(n, 0);
  EXPECT_DOUBLE_EQ(r.removed, double(n) * 0.125);
  EXPECT_TRUE(r.incidents.empty());
  EXPECT_TRUE(sim.report().clean());
  // Flat: every column of the hole ends at z = 4 mm (index 8).
  EXPECT_EQ(removed(full_stock(), sim).bounding_box().lo.z, 8);
  EXPECT_FALSE(sim.stock().contains({20, 20, 8}));
  EXPECT_TRUE(sim.stock().contains({20, 20, 7}));
}

TEST(MaterialSimulation, AShankFollowsItsCutterDownWithoutTouchingButAWiderOneCollides) {
  // A 3 mm flute plunging 6 mm deep: the shank ends up inside the hole the flutes cut.
  MaterialSimulation same(full_stock());
  same.cut(cutter_of(tool(config::ToolType::Flat, 4, 3, {4, 8})), feed({10, 10, 12}, {10, 10, 4}, 5));
  EXPECT_TRUE(same.report().clean()) << describe(same.report().incidents.front());
  const Solid hole = geometry::make_cylinder(kLattice, geometry::Axis::Z, {10, 10, 4}, 2, 100);
  EXPECT_EQ(same.stock(), geometry::subtract(full_stock(), hole));

  MaterialSimulation wide(full_stock());
  const MoveReport r = wide.cut(cutter_of(tool(config::ToolType::Flat, 4, 3, {6, 8})), feed({10, 10, 12}, {10, 10, 4}, 9));
  ASSERT_EQ(r.incidents.size(), 1u);
  const Incident& i = r.incidents.front();
  EXPECT_EQ(i.kind, IncidentKind::BodyCollision);
  EXPECT_EQ(i.line, 9);
  // The ring between the shank (r 3) and the cutter (r 2), from the final shank bottom
  // at 7 mm up to the stock top.
  const Solid ring = geometry::subtract(geometry::make_cylinder(kLattice, geometry::Axis::Z, {10, 10, 7}, 3, 100), hole);
  EXPECT_EQ(i.voxels, geometry::intersect(ring, full_stock()).voxel_count());
  EXPECT_NEAR(i.region.min.z, 6.75, 1e-12);
  EXPECT_NEAR(i.region.max.z, 10.25, 1e-12);
}

TEST(MaterialSimulation, ABallMillSlotHasARoundBottom) {
  const Cutter ball = cutter_of(tool(config::ToolType::Ball, 4, 8, {4, 8}));
  MaterialSimulation sim(full_stock());
  sim.cut(ball, feed({5, 10, 6}, {15, 10, 6}, 3));
  const Solid cut = removed(full_stock(), sim);
  // Across the middle of the slot (x = 10): a half-disc of radius 2 around (y 10, z 8)
  // below the ball centre, straight walls above.
  int deepest_centre = 100, deepest_side = 100;
  for (int k = 0; k < kStockBox.hi.z; ++k)
    for (int j = 0; j < kStockBox.hi.y; ++j) {
      const double y = 0.5 * j, z = 0.5 * k;
      const bool expected = z >= 8 ? std::abs(y - 10) <= 2 : (y - 10) * (y - 10) + (z - 8) * (z - 8) <= 4;
      EXPECT_EQ(cut.contains({20, j, k}), expected) << "y " << y << " z " << z;
      if (cut.contains({20, j, k}) && j == 20) deepest_centre = std::min(deepest_centre, k);
      if (cut.contains({20, j, k}) && j == 23) deepest_side = std::min(deepest_side, k);
    }
  EXPECT_EQ(deepest_centre, 12);  // 6 mm: the tip
  EXPECT_EQ(deepest_side, 14);    // 7 mm: 1.5 mm aside the bottom rises to 8 - sqrt(1.75) = 6.68
}

TEST(MaterialSimulation, ACutRemovesExactlyTheSweptVolumeOfTheCuttingPart) {
  config::CuttingTool bull_tool = tool(config::ToolType::Bull, 5, 6, {5, 8});
  bull_tool.corner_radius = 1;
  const Cutter bull = cutter_of(bull_tool);
  for (const auto& [a, b] : std::vector<std::pair<Vec3, Vec3>>{
           {{3.3, 4.1, 9.0}, {16.2, 12.7, 5.5}}, {{14, 3, 4.2}, {6.1, 17, 4.2}}, {{10, 10, 11}, {10.4, 9.8, 3.3}}}) {
    MaterialSimulation sim(full_stock());
    sim.cut(bull, feed(a, b, 1));
    const Solid swept = swept_volume(pieces_of(bull.cutting), {a, b}, kLattice, kStockBox);
    EXPECT_EQ(removed(full_stock(), sim), swept);
    EXPECT_DOUBLE_EQ(sim.report().removed, swept.volume());
  }
}

// A cylinder moved level or along its axis sweeps one interval per y at every height
// inside its slab, which the simulation works out once per y: the cut is still exactly
// the swept volume, slab edges on a decimal lattice included (and a ramp, row by row).
TEST(MaterialSimulation, AFlatMillMovedLevelOrPlungedRemovesExactlyItsSweptVolume) {
  const geometry::Lattice decimal{0.1, {0, 0, 0}};
  const IndexBox box{{0, 0, 0}, {60, 60, 40}};
  const Cutter flat = cutter_of(tool(config::ToolType::Flat, 1.3, 1.7, {1.3, 2.5}));
  for (const auto& [a, b] : std::vector<std::pair<Vec3, Vec3>>{{{0.55, 1.05, 1.25}, {4.85, 3.3, 1.25}},
                                                                {{3.0, 3.0, 0.35}, {3.0, 3.0, 0.35}},
                                                                {{2.05, 2.95, 3.45}, {2.05, 2.95, 0.25}},
                                                                {{1.0, 4.4, 0.15}, {1.0, 4.4, 2.65}},
                                                                {{5.0, 0.8, 2.0}, {0.9, 0.8, 2.0}},
                                                                {{0.7, 0.9, 0.3}, {4.6, 4.1, 2.9}}}) {  // a ramp
    MaterialSimulation sim(Solid::filled(decimal, box));
    sim.cut(flat, feed(a, b, 1));
    const Solid swept = swept_volume(pieces_of(flat.cutting), {a, b}, decimal, box);
    EXPECT_GT(swept.volume(), 0);
    EXPECT_EQ(removed(Solid::filled(decimal, box), sim), swept);
  }
}

// The box the sweeps are clipped to shrinks as cuts empty its top layers (a tool working
// down level by level sweeps its holder through air): what remains is still met, by the
// holder one voxel layer below the cut and by a rapid, and a bead laid on top again.
TEST(MaterialSimulation, AfterCutsClearTheTopWhatRemainsAndWhatIsLaidAgainAreStillMet) {
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 4, 2, {4, 3}, {30, 40}));  // holder from 5 mm up
  MaterialSimulation sim(full_stock());
  for (int pass = 0; pass <= 6; ++pass) {  // the top 2 mm cleared: voxel centres 8 mm and up
    const double y = -1.5 + 3.5 * pass;
    sim.cut(mill, feed({-3, y, 8}, {23, y, 8}, 10 + pass));
  }
  EXPECT_EQ(sim.stock().bounding_box().hi.z, 16);  // centres up to 7.5 mm remain
  EXPECT_TRUE(sim.cut(mill, rapid({10, 10, 30}, {10, 10, 8.1}, 20)).incidents.empty());
  EXPECT_EQ(count_of(sim.cut(mill, rapid({10, 10, 8.1}, {10, 10, 7.4}, 21)).incidents, IncidentKind::RapidIntoMaterial), 1);
  // The holder's face at 2.4 + 5 mm reaches the centres at 7.5 mm; at 2.6 + 5 it does not.
  EXPECT_EQ(count_of(sim.cut(mill, feed({-10, 10, 2.6}, {-3, 10, 2.6}, 22)).incidents, IncidentKind::BodyCollision), 0);
  EXPECT_EQ(count_of(sim.cut(mill, feed({-10, 10, 2.4}, {-3, 10, 2.4}, 23)).incidents, IncidentKind::BodyCollision), 1);
  const Bead bead{config::BeadShape::Cylinder, 2, 1, {}, {}};
  EXPECT_GT(sim.deposit(bead, {Motion::Linear, {5, 5, 8}, {15, 5, 8}, {}, true, 24}).deposited, 0);
  EXPECT_EQ(count_of(sim.cut(mill, rapid({10, 5, 30}, {10, 5, 8.6}, 25)).incidents, IncidentKind::RapidIntoMaterial), 1);
}

TEST(MaterialSimulation, ARapidIntoMaterialRaisesAnIncidentNamingTheLine) {
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 4, 8, {4, 8}));
  MaterialSimulation sim(full_stock());
  EXPECT_TRUE(sim.cut(mill, rapid({10, 10, 30}, {10, 10, 11}, 41)).incidents.empty());  // above the stock
  EXPECT_TRUE(sim.cut(mill, rapid({10, 10, 11}, {2, 3, 11}, 42)).incidents.empty());
  const MoveReport r = sim.cut(mill, rapid({2, 3, 11}, {2, 3, 8}, 43));
  ASSERT_EQ(r.incidents.size(), 1u);
  const Incident& i = r.incidents.front();
  EXPECT_EQ(i.kind, IncidentKind::RapidIntoMaterial);
  EXPECT_EQ(i.line, 43);
  EXPECT_EQ(i.to, (Vec3{2, 3, 8}));
  const Solid hole = geometry::intersect(full_stock(), geometry::make_cylinder(kLattice, geometry::Axis::Z, {2, 3, 8}, 2, 100));
  EXPECT_EQ(i.voxels, hole.voxel_count());
  EXPECT_DOUBLE_EQ(i.volume, hole.volume());
  EXPECT_NEAR(i.region.min.z, 7.75, 1e-12);
  const std::string text = describe(i);
  EXPECT_NE(text.find("line 43"), std::string::npos) << text;
  EXPECT_NE(text.find("rapid into material"), std::string::npos) << text;
  // The spindle turns: the rapid cut its way in.
  EXPECT_EQ(sim.stock(), geometry::subtract(full_stock(), hole));
  EXPECT_EQ(sim.report().incidents.size(), 1u);
  EXPECT_DOUBLE_EQ(sim.report().rapid_contact, hole.volume());
}

TEST(MaterialSimulation, ARapidGrazingMaterialWithTheHolderIsAnIncidentToo) {
  // The tip is above the stock but the wide holder is not: a rapid along X through a
  // pocket whose walls the holder sweeps.
  Solid stock = full_stock();
  stock = geometry::subtract(stock, Solid::filled(kLattice, {{10, 10, 8}, {31, 31, 21}}));  // pocket 5..15, z >= 4
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 2, 2, {2, 1}, {12, 20}));
  MaterialSimulation sim(stock);
  // Tip at 4.5 mm: the cutter ends at 6.5, the shank at 7.5, the holder (r 6) above.
  const MoveReport r = sim.cut(mill, rapid({10, 10, 4.5}, {10, 10.5, 4.5}, 12));
  ASSERT_EQ(count_of(r.incidents, IncidentKind::RapidIntoMaterial), 1);
  EXPECT_EQ(r.removed, 0);
  EXPECT_GT(r.rapid_contact, 0);
}

TEST(MaterialSimulation, AHolderOrShankInMaterialIsACollisionOnThatLine) {
  const Cutter short_fluted = cutter_of(tool(config::ToolType::Flat, 4, 3, {4, 2}, {20, 30}));
  {
    // Tip 6 mm below the top: flutes reach 7, shank 7..9, holder from 9 mm: both drag
    // through material.
    MaterialSimulation sim(full_stock());
    const MoveReport r = sim.cut(short_fluted, feed({3, 10, 4}, {17, 10, 4}, 7));
    ASSERT_EQ(r.incidents.size(), 1u);
    EXPECT_EQ(r.incidents.front().kind, IncidentKind::BodyCollision);
    EXPECT_EQ(r.incidents.front().line, 7);
    const Solid cut = swept_volume(pieces_of(short_fluted.cutting), {{3, 10, 4}, {17, 10, 4}}, kLattice, kStockBox);
    const Solid body = swept_volume(pieces_of(short_fluted.body), {{3, 10, 4}, {17, 10, 4}}, kLattice, kStockBox);
    const Solid touched = geometry::subtract(geometry::intersect(body, full_stock()), cut);
    EXPECT_EQ(r.incidents.front().voxels, touched.voxel_count());
    EXPECT_DOUBLE_EQ(r.collision, touched.volume());
    EXPECT_EQ(sim.stock(), geometry::subtract(full_stock(), cut));  // the body does not cut
  }
  {
    // 2 mm deep: the flutes reach past the top, nothing else touches.
    MaterialSimulation sim(full_stock());
    EXPECT_TRUE(sim.cut(short_fluted, feed({3, 10, 8}, {17, 10, 8}, 8)).incidents.empty());
    EXPECT_GT(sim.report().removed, 0);
  }
  {
    // Retracting straight up out of a hole through a ledge left above it: the shank,
    // as wide as the flutes, rises into the ledge before the flutes could clear it.
    const Cutter long_shank = cutter_of(tool(config::ToolType::Flat, 4, 3, {4, 20}, {20, 30}));
    Solid stock = geometry::subtract(full_stock(), Solid::filled(kLattice, {{0, 0, 12}, {41, 41, 21}}));  // top 5.5
    stock = geometry::unite(stock, Solid::filled(kLattice, {{0, 0, 19}, {41, 41, 21}}));              // ledge 9.5..10
    MaterialSimulation sim(stock);
    const MoveReport r = sim.cut(long_shank, feed({10, 10, 3.5}, {10, 10, 7.5}, 11));
    ASSERT_EQ(count_of(r.incidents, IncidentKind::BodyCollision), 1);
    // What the shank (r 2, from 6.5 mm at the start) meets of the ledge.
    const Solid shank = geometry::make_cylinder(kLattice, geometry::Axis::Z, {10, 10, 6.5}, 2, 100);
    EXPECT_EQ(r.incidents.front().voxels, geometry::intersect(shank, stock).voxel_count());
    // The same move going down meets the ledge with the flutes first: no collision.
    MaterialSimulation down(stock);
    EXPECT_EQ(count_of(down.cut(long_shank, feed({10, 10, 7.5}, {10, 10, 3.5}, 12)).incidents,
                       IncidentKind::BodyCollision),
              0);
  }
}

TEST(MaterialSimulation, VoxelCentresExactlyOnTheToolSurfaceAreCutOnDecimalLattices) {
  // 0.1 mm voxels: radii and positions are not exact in binary, the ties still count.
  const geometry::Lattice decimal{0.1, {0, 0, 0}};
  const IndexBox box{{0, 0, 0}, {21, 21, 10}};
  for (const double radius : {0.3, 0.5, 0.7, 1.0}) {
    MaterialSimulation sim(Solid::filled(decimal, box));
    const double c = decimal.center({10, 10, 0}).x;  // 1.05
    sim.cut(cutter_of(tool(config::ToolType::Flat, 2 * radius, 5, {2 * radius, 5})),
            feed({c, c, 2}, {c, c, decimal.center({0, 0, 4}).z}, 1));
    const int n = int(std::lround(radius * 10));
    for (int j = 0; j < 21; ++j)
      for (int i = 0; i < 21; ++i) {
        const bool in_tool = (i - 10) * (i - 10) + (j - 10) * (j - 10) <= n * n;
        EXPECT_EQ(sim.stock().contains({i, j, 4}), !in_tool) << "radius " << radius << " at " << i << "," << j;
        EXPECT_TRUE(sim.stock().contains({i, j, 3}));
      }
  }
}

TEST(MaterialSimulation, CuttingIntoTheProtectedSolidIsAGougeOnThatLine) {
  const Solid design = Solid::filled(kLattice, {{16, 16, 0}, {25, 25, 13}});  // 8..12 mm, up to 6 mm
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 4, 8, {4, 8}));
  MaterialSimulation sim(full_stock(), design);
  EXPECT_TRUE(sim.cut(mill, feed({2, 10, 6.5}, {18, 10, 6.5}, 20)).incidents.empty());  // just above
  const MoveReport r = sim.cut(mill, feed({2, 10, 5}, {18, 10, 5}, 21));
  ASSERT_EQ(r.incidents.size(), 1u);
  EXPECT_EQ(r.incidents.front().kind, IncidentKind::Gouge);
  EXPECT_EQ(r.incidents.front().line, 21);
  const Solid swept = swept_volume(pieces_of(mill.cutting), {{2, 10, 5}, {18, 10, 5}}, kLattice, kStockBox);
  const Solid gouged = geometry::intersect(swept, design);  // z 5 .. 6 mm: 3 layers
  EXPECT_EQ(r.incidents.front().voxels, gouged.voxel_count());
  EXPECT_DOUBLE_EQ(r.gouge, gouged.volume());
  EXPECT_DOUBLE_EQ(sim.report().gouge, gouged.volume());
  EXPECT_NEAR(r.incidents.front().region.min.z, 4.75, 1e-12);
  EXPECT_NEAR(r.incidents.front().region.max.z, 6.25, 1e-12);
  EXPECT_THROW(MaterialSimulation(full_stock(), Solid(geometry::Lattice{0.25, {}}, kStockBox)), std::invalid_argument);
}

TEST(MaterialSimulation, ArcsCutWithinTheChordToleranceOfTheTrueArc) {
  const double r = 2, flute = 20, arc_radius = 6;
  const Cutter mill = cutter_of(tool(config::ToolType::Flat, 2 * r, flute, {4, 8}));
  const Vec3 c{10, 10, 0};
  for (Motion m : {Motion::ArcCcw, Motion::ArcCw}) {
    MaterialSimulation sim(full_stock());  // default tolerance: a tenth of a voxel
    const Vec3 from{c.x + arc_radius, c.y, 5}, to{c.x - arc_radius * std::sqrt(0.5), c.y + arc_radius * std::sqrt(0.5), 5};
    sim.cut(mill, {m, from, to, c, false, 30});
    const Solid got = removed(full_stock(), sim);
    // Dense samples of the true arc.
    const double a0 = 0, a1 = m == Motion::ArcCcw ? 0.75 * std::numbers::pi : -1.25 * std::numbers::pi;
    const int n = 4000;
    std::vector<Vec3> arc;
    for (int i = 0; i <= n; ++i) {
      const double a = a0 + (a1 - a0) * i / n;
      arc.push_back({c.x + arc_radius * std::cos(a), c.y + arc_radius * std::sin(a), 5});
    }
    const double tol = 0.05, gap = arc_radius * std::abs(a1 - a0) / n;
    const std::vector<AxialSection> cutter = flat_mill(r, flute);
    const Solid inner = geometry::intersect(
        placed_union(sections_shape(cutter, -tol), arc, r, 0, flute, kStockBox), full_stock());
    const Solid outer = geometry::intersect(
        placed_union(sections_shape(cutter, tol + gap / 2 + 1e-9), arc, r + 1, -1, flute + 1, kStockBox), full_stock());
    EXPECT_TRUE(subset(inner, got)) << geometry::subtract(inner, got).voxel_count();
    EXPECT_TRUE(subset(got, outer)) << geometry::subtract(got, outer).voxel_count();
    // Not vacuous: the bounds differ by the voxels within about a tenth of a voxel of the
    // swept boundary.
    EXPECT_LT(double(outer.voxel_count() - inner.voxel_count()), 0.2 * double(got.voxel_count()));
    EXPECT_TRUE(sim.report().clean());
  }
}

// Deposition on a fine lattice on a build plate at z = 0.
const geometry::Lattice kFine{0.125, {0, 0, 0}};
const IndexBox kPlateBox{{0, 0, 0}, {200, 64, 24}};  // 25 x 8 x 3 mm

// The voxel of kFine holding a point (mm).
geometry::Index3 voxel_at(double x, double y, double z) {
  return {int(std::floor(x / kFine.voxel_size)), int(std::floor(y / kFine.voxel_size)), int(std::floor(z / kFine.voxel_size))};
}

TEST(MaterialSimulation, ABeadDepositsItsSweptVolume) {
  const double length = 20;
  {
    MaterialSimulation sim(Solid(kFine, kPlateBox));
    const Bead bead{config::BeadShape::Ellipsoid, 2, 1, {}, {}};
    const MoveReport r = sim.deposit(bead, {Motion::Linear, {2, 3, 0}, {2 + length, 3, 0}, {}, true, 50});
    // Its upper half an elliptic cylinder with a quarter ellipsoid at each end, its lower
    // half (below the widest line, 0.5 mm) a box with half a round slab at each end.
    const double upper = std::numbers::pi * 1 * 0.5 / 2 * length + 2.0 / 3 * std::numbers::pi * 1 * 1 * 0.5;
    const double lower = 2 * 1 * 0.5 * length + std::numbers::pi * 1 * 1 * 0.5;
    const double expected = upper + lower;
    EXPECT_NEAR(r.deposited, expected, 0.02 * expected);
    EXPECT_DOUBLE_EQ(r.deposited, sim.stock().volume());
    EXPECT_EQ(r.overlap, 0);
    EXPECT_TRUE(r.incidents.empty());
    // The bead lies on the programmed point: bottom at z = 0, top at 1 mm.
    const geometry::Box3 bb = sim.stock().bounding_box_mm();
    EXPECT_NEAR(bb.min.z, 0, 1e-12);
    EXPECT_NEAR(bb.max.z, 1, 1e-12);
    EXPECT_NEAR(bb.min.x, 1, 0.13);
    EXPECT_NEAR(bb.max.x, 23, 0.13);
  }
  {
    MaterialSimulation sim(Solid(kFine, kPlateBox));
    const Bead bead{config::BeadShape::Cylinder, 2, 1, {}, {}};
    const MoveReport r = sim.deposit(bead, {Motion::Linear, {2, 3, 0}, {2 + length, 3, 0}, {}, true, 51});
    const double expected = 2 * 1 * length + std::numbers::pi * 1 * 1 * 1;  // box with round ends
    EXPECT_NEAR(r.deposited, expected, 0.02 * expected);
  }
}

TEST(MaterialSimulation, OverlapUnsupportedAndLostDepositionAreReported) {
  const Bead bead{config::BeadShape::Ellipsoid, 2, 1, {}, {}};
  MaterialSimulation sim(Solid(kFine, kPlateBox));
  const Segment first{{2, 3, 0}, {20, 3, 0}};
  sim.deposit(bead, {Motion::Linear, first.from, first.to, {}, true, 60});
  // The next layer 0.8 mm up re-melts the top of the first.
  const Segment second{{2, 3, 0.8}, {20, 3, 0.8}};
  const MoveReport r = sim.deposit(bead, {Motion::Linear, second.from, second.to, {}, true, 61});
  const Solid first_bead = swept_volume(pieces_of(bead), first, kFine, kPlateBox);
  const Solid second_bead = swept_volume(pieces_of(bead), second, kFine, kPlateBox);
  EXPECT_DOUBLE_EQ(r.overlap, geometry::intersect(first_bead, second_bead).volume());
  EXPECT_GT(r.overlap, 0);
  EXPECT_DOUBLE_EQ(r.deposited + r.overlap, second_bead.volume());
  EXPECT_TRUE(r.incidents.empty());

  // Beside the wall, half a millimetre above the plate: nothing below, so it all falls.
  const Solid before = sim.stock();
  const Segment over_air{{2, 6, 0.5}, {20, 6, 0.5}};
  const MoveReport air = sim.deposit(bead, {Motion::Linear, over_air.from, over_air.to, {}, true, 62});
  ASSERT_EQ(air.incidents.size(), 1u);
  EXPECT_EQ(air.incidents.front().kind, IncidentKind::UnsupportedDeposition);
  EXPECT_EQ(air.incidents.front().line, 62);
  EXPECT_EQ(air.deposited, 0);
  EXPECT_DOUBLE_EQ(air.incidents.front().volume, swept_volume(pieces_of(bead), over_air, kFine, kPlateBox).volume());
  EXPECT_EQ(sim.stock(), before);

  // Running along the domain's side at y = 8 mm: the bead's outer half is lost.
  const Segment edge{{15, 7.5, 0}, {20, 7.5, 0}};
  const MoveReport lost = sim.deposit(bead, {Motion::Linear, edge.from, edge.to, {}, true, 63});
  ASSERT_EQ(count_of(lost.incidents, IncidentKind::DepositionOutsideDomain), 1);
  const Solid whole = swept_volume(pieces_of(bead), edge, kFine, {{0, 0, 0}, {200, 100, 24}});
  EXPECT_GT(lost.outside, 0);
  EXPECT_DOUBLE_EQ(lost.deposited + lost.overlap + lost.outside, whole.volume());
  EXPECT_NEAR(lost.incidents.back().region.min.y, 8, 1e-12);
  EXPECT_NEAR(lost.incidents.back().region.max.y, 8.5, 1e-12);
}

TEST(MaterialSimulation, ABeadOffAnEdgeKeepsWhatTheHeadsConeHoldsAndTheRestFalls) {
  // A block 10 mm long, 2 mm high; a cylinder bead 1 mm wide laid on its top from x 2 to 20.
  const Solid block = geometry::make_box(kFine, {{0, 0, 0}, {10, 8, 2}});
  Solid world(kFine, kPlateBox);
  world = geometry::unite(world, block);
  Bead bead{config::BeadShape::Cylinder, 1, 0.5, {}, {}};
  bead.support = {45, 0};
  MaterialSimulation sim(world);
  const MoveReport r = sim.deposit(bead, {Motion::Linear, {2, 4, 2}, {20, 4, 2}, {}, true, 80});
  ASSERT_EQ(count_of(r.incidents, IncidentKind::UnsupportedDeposition), 1);
  // Held: on the block and up to the cone's reach beyond its edge (tan 45 + 1 voxel of
  // slack = 2 voxels of 0.125 mm); what fell starts there and runs to the bead's end.
  const Solid added = geometry::subtract(sim.stock(), world);
  EXPECT_NEAR(added.bounding_box_mm().max.x, 10.25, 1e-9);
  const Incident& fell = r.incidents.front();
  EXPECT_NEAR(fell.region.min.x, 10.25, 1e-9);
  EXPECT_NEAR(fell.region.max.x, 20.5, 1e-9);
  EXPECT_DOUBLE_EQ(r.deposited + fell.volume, swept_volume(pieces_of(bead), {{2, 4, 2}, {20, 4, 2}}, kFine, kPlateBox).volume());
}

TEST(MaterialSimulation, ABeadBridgesAGapWithinTheHeadsSpanOnly) {
  // Two blocks with a gap between them; a bead across it on their tops.
  auto gap_world = [](double gap) {
    Solid w(kFine, kPlateBox);
    w = geometry::unite(w, geometry::make_box(kFine, {{0, 0, 0}, {5, 8, 2}}));
    return geometry::unite(w, geometry::make_box(kFine, {{5 + gap, 0, 0}, {12 + gap, 8, 2}}));
  };
  Bead bead{config::BeadShape::Cylinder, 1, 0.5, {}, {}};
  bead.support = {0, 2};  // no overhang; bridges up to 2 mm
  for (const double gap : {1.5, 3.0}) {
    SCOPED_TRACE(gap);
    MaterialSimulation sim(gap_world(gap));
    const MoveReport r = sim.deposit(bead, {Motion::Linear, {1, 4, 2}, {10 + gap, 4, 2}, {}, true, 90});
    const bool spans = gap - 2 * 0.125 <= 2;  // the cone's slack holds one voxel at each edge
    EXPECT_EQ(count_of(r.incidents, IncidentKind::UnsupportedDeposition), spans ? 0 : 1);
    EXPECT_EQ(sim.stock().contains(voxel_at(5 + gap / 2, 4, 2.1)), spans);
  }
}

TEST(MaterialSimulation, TheHeadsNozzleStandsOffAndCollidesWithWhatItMeets) {
  config::AdditiveHead head;
  head.bead = {config::BeadShape::Cylinder, 1, 0.5};
  head.nozzle = config::Nozzle{4, 10, 2};
  const Bead bead = bead_of(head);
  ASSERT_EQ(bead.body.size(), 1u);
  EXPECT_EQ(bead.body[0].from, 2);
  EXPECT_EQ(bead.body[0].to, 12);
  // A wall 2.5 mm high beside a track on the plate: the bead passes 1 mm from it, the
  // nozzle (radius 2, from 2 mm up) meets its top half millimetre.
  Solid world(kFine, kPlateBox);
  world = geometry::unite(world, geometry::make_box(kFine, {{0, 5, 0}, {25, 8, 2.5}}));
  MaterialSimulation sim(world);
  const MoveReport r = sim.deposit(bead, {Motion::Linear, {2, 4, 0}, {20, 4, 0}, {}, true, 100});
  ASSERT_EQ(count_of(r.incidents, IncidentKind::BodyCollision), 1);
  EXPECT_NEAR(r.incidents.front().region.min.z, 2, 1e-9);
  // Beside a wall lower than the stand-off, nothing touches.
  Solid low(kFine, kPlateBox);
  low = geometry::unite(low, geometry::make_box(kFine, {{0, 5, 0}, {25, 8, 1.5}}));
  MaterialSimulation clear(low);
  EXPECT_TRUE(clear.deposit(bead, {Motion::Linear, {2, 4, 0}, {20, 4, 0}, {}, true, 101}).incidents.empty());
}

TEST(MaterialSimulation, HeadTravelChecksRapidsAgainstMaterial) {
  const Bead bead{config::BeadShape::Ellipsoid, 2, 1, {}, {}};
  MaterialSimulation sim(Solid(kFine, kPlateBox));
  sim.deposit(bead, {Motion::Linear, {2, 3, 0}, {20, 3, 0}, {}, true, 70});
  // Feed without deposition over the bead: the melt zone is no body, nothing to report.
  EXPECT_TRUE(sim.deposit(bead, {Motion::Linear, {20, 3, 0.8}, {2, 3, 0.8}, {}, false, 71}).incidents.empty());
  // A rapid at the same height runs the head into the bead; lifted clear it does not.
  const MoveReport r = sim.deposit(bead, {Motion::Rapid, {20, 3, 0.8}, {2, 3, 0.8}, {}, false, 72});
  ASSERT_EQ(r.incidents.size(), 1u);
  EXPECT_EQ(r.incidents.front().kind, IncidentKind::RapidIntoMaterial);
  EXPECT_EQ(r.incidents.front().line, 72);
  EXPECT_TRUE(sim.deposit(bead, {Motion::Rapid, {20, 3, 1.1}, {2, 3, 1.1}, {}, false, 73}).incidents.empty());
  // With a nozzle body, a feed move dragging it through material collides.
  Bead with_nozzle = bead;
  with_nozzle.body = {{Kind::Cylinder, 1.0, 2.0, 1.5, 0, 0}};
  const MoveReport drag = sim.deposit(with_nozzle, {Motion::Linear, {20, 3, -0.5}, {2, 3, -0.5}, {}, false, 74});
  EXPECT_EQ(count_of(drag.incidents, IncidentKind::BodyCollision), 1);
}

}  // namespace
}  // namespace hybridctl::sim
