// Tool sweeps are exact: every sweep equals, voxel for voxel, its definition computed with
// brute-force Minkowski sums, (complement of U_i (S (+) -C_i)) (+) B within the domain,
// whichever way it is computed (heightmaps per column, or dilations) and however many
// sweeps share one call.

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "geometry/morphology.hpp"
#include "geometry/shapes.hpp"

namespace hybridctl::geometry {
namespace {

const Lattice kLattice{0.5, {0, 0, 0}};
constexpr double kNoEnd = std::numeric_limits<double>::infinity();

// A solid with an overhang, a hole through it, a sphere and scattered voxels: columns
// that are free from one side only, free twice, or not at all.
Solid overhanging(std::uint32_t seed) {
  Solid s = unite(make_box(kLattice, {{2, 2, 0}, {4, 4, 3}}), make_box(kLattice, {{0, 0, 3}, {7, 6, 4}}));
  s = subtract(s, make_box(kLattice, {{5, 1, 2.5}, {6, 2, 4.5}}));
  s = unite(s, make_sphere(kLattice, {8, 4, 1.5}, 1.2));
  std::mt19937 rng(seed);
  Solid scattered(kLattice, {{-2, -2, -2}, {18, 14, 10}});
  for (int i = 0; i < 8; ++i) scattered.set({int(rng() % 20) - 2, int(rng() % 16) - 2, int(rng() % 12) - 2});
  return unite(s, scattered);
}

const IndexBox kDomain{{-5, -5, -5}, {22, 17, 14}};

// Cutting parts (from the tip) and what holds them (shank, holder that never ends).
std::vector<AxialSection> flat() { return {{AxialSection::Kind::Cylinder, 0, 1.5, 1.0, 0, 0}}; }
std::vector<AxialSection> ball() {
  return {{AxialSection::Kind::Sphere, 0, 1.0, 1.0, 1.0, 0}, {AxialSection::Kind::Cylinder, 1.0, 1.5, 1.0, 0, 0}};
}
std::vector<AxialSection> bull() {
  return {{AxialSection::Kind::Torus, 0, 0.5, 0.5, 0.5, 0.5}, {AxialSection::Kind::Cylinder, 0.5, 1.5, 1.0, 0, 0}};
}
std::vector<AxialSection> holder(double shank_radius) {
  return {{AxialSection::Kind::Cylinder, 1.5, 2.5, shank_radius, 0, 0}, {AxialSection::Kind::Cylinder, 2.5, kNoEnd, 1.8, 0, 0}};
}

// The definition, with brute-force sums: tips whose clearance misses the solid, swept.
Solid sweep_by_definition(const Solid& s, const ToolSweep& sweep, const IndexBox& domain) {
  const IndexBox ext = element_extent(reflected(sweep.cutting), s.voxel_size());
  const IndexBox tips{{domain.lo.x + ext.lo.x, domain.lo.y + ext.lo.y, domain.lo.z + ext.lo.z},
                      {domain.hi.x + ext.hi.x - 1, domain.hi.y + ext.hi.y - 1, domain.hi.z + ext.hi.z - 1}};
  Solid obstacle = intersect(s, Solid::filled(kLattice, tips));
  if (!sweep.clearance.empty()) {
    obstacle = Solid(kLattice, tips);
    for (const AxialBody& c : sweep.clearance)
      obstacle = unite(obstacle, dilate(s, reflected(c), tips, MorphologyMethod::BruteForce));
  }
  return dilate(complement(obstacle, tips), sweep.cutting, domain, MorphologyMethod::BruteForce);
}

std::vector<AxisDirection> all_directions() {
  return {{Axis::X, +1}, {Axis::X, -1}, {Axis::Y, +1}, {Axis::Y, -1}, {Axis::Z, +1}, {Axis::Z, -1}};
}

ToolSweep tool(AxisDirection d, std::vector<AxialSection> cutting, double shank_radius, bool whole_tool) {
  ToolSweep s{{d, std::move(cutting)}, {{d, holder(shank_radius)}}};
  if (whole_tool) s.clearance.push_back(s.cutting);
  return s;
}

TEST(ToolSweeps, ACutterInAHolderThatWidensEqualsTheDefinitionFromEverySide) {
  const Solid s = overhanging(3);
  for (const AxisDirection d : all_directions())
    for (const auto& [name, cutting] : {std::pair{"flat", flat()}, {"ball", ball()}, {"bull", bull()}})
      for (bool whole_tool : {true, false}) {
        const ToolSweep sweep = tool(d, cutting, 1.0, whole_tool);
        const Solid fast = tool_sweeps(s, {sweep}, kDomain).front();
        EXPECT_EQ(fast, sweep_by_definition(s, sweep, kDomain))
            << name << " along axis " << int(d.axis) << " sign " << d.sign << (whole_tool ? " (SM-max)" : " (SM-cons)");
        EXPECT_FALSE(fast.empty());
      }
}

TEST(ToolSweeps, ANarrowNeckOrAClearanceThatEndsEqualsTheDefinitionToo) {
  const Solid s = overhanging(5);
  for (const AxisDirection d : {AxisDirection{Axis::Z, +1}, AxisDirection{Axis::X, -1}}) {
    // A reduced neck (narrower than the cutter) between cutter and holder.
    const ToolSweep neck = tool(d, flat(), 0.5, true);
    EXPECT_EQ(tool_sweeps(s, {neck}, kDomain).front(), sweep_by_definition(s, neck, kDomain));
    // A finite clearance (no holder) and none at all (the tip alone must miss the solid).
    const ToolSweep finite{{d, ball()}, {{d, {{AxialSection::Kind::Cylinder, 0, 2.0, 1.2, 0, 0}}}}};
    EXPECT_EQ(tool_sweeps(s, {finite}, kDomain).front(), sweep_by_definition(s, finite, kDomain));
    const ToolSweep bare{{d, bull()}, {}};
    EXPECT_EQ(tool_sweeps(s, {bare}, kDomain).front(), sweep_by_definition(s, bare, kDomain));
  }
}

TEST(ToolSweeps, ACuttingPartAwayFromTheTipEqualsTheDefinition) {
  const Solid s = overhanging(7);
  const AxisDirection d{Axis::Y, +1};
  const ToolSweep ring{{d, {{AxialSection::Kind::Cylinder, 0.5, 1.5, 1.0, 0, 0}}}, {{d, holder(1.0)}}};
  EXPECT_EQ(tool_sweeps(s, {ring}, kDomain).front(), sweep_by_definition(s, ring, kDomain));
}

TEST(ToolSweeps, SweepsInOneCallEqualEachAlone) {
  const Solid s = overhanging(11);
  std::vector<ToolSweep> sweeps;
  for (const AxisDirection d : all_directions()) {
    sweeps.push_back(tool(d, flat(), 1.0, true));
    sweeps.push_back(tool(d, ball(), 0.5, false));
    sweeps.push_back(tool(d, bull(), 1.0, false));
  }
  std::vector<std::size_t> reported;
  const std::vector<Solid> together = tool_sweeps(s, sweeps, kDomain, [&](std::size_t i) { reported.push_back(i); });
  ASSERT_EQ(together.size(), sweeps.size());
  EXPECT_EQ(reported.size(), sweeps.size());
  for (std::size_t i = 0; i < sweeps.size(); ++i) EXPECT_EQ(together[i], tool_sweeps(s, {sweeps[i]}, kDomain).front()) << i;
}

TEST(ToolSweeps, NothingInTheWayIsTheWholeDomainAndAnEmptyCutterSweepsNothing) {
  const Solid none(kLattice, {});
  const ToolSweep sweep = tool({Axis::Z, +1}, flat(), 1.0, true);
  EXPECT_EQ(tool_sweeps(none, {sweep}, kDomain).front(), Solid::filled(kLattice, kDomain));
  const ToolSweep nothing{{{Axis::Z, +1}, {}}, sweep.clearance};
  EXPECT_TRUE(tool_sweeps(overhanging(1), {nothing}, kDomain).front().empty());
}

TEST(ToolSweeps, TheHolderKeepsTheToolOutOfTheShadowOfAnOverhang) {
  // A 4 mm slab at z = 3..4 mm over air: from +Z no tip reaches under it, from -Z all of it.
  const Solid slab = make_box(kLattice, {{0, 0, 3}, {4, 4, 4}});
  const Index3 under{4, 4, 2};  // (2.25, 2.25, 1.25) mm
  EXPECT_FALSE(tool_sweeps(slab, {tool({Axis::Z, +1}, flat(), 1.0, true)}, kDomain).front().contains(under));
  EXPECT_TRUE(tool_sweeps(slab, {tool({Axis::Z, -1}, flat(), 1.0, true)}, kDomain).front().contains(under));
}

}  // namespace
}  // namespace hybridctl::geometry
