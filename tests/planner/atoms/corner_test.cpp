// Why hybrid planning exists: a part with a sharp outer corner and a sharp inner corner.
// A round bead cannot deposit a sharp outer corner and a ball mill cannot cut a sharp
// inner one, so neither process alone makes this part; a near-net plate, milled to its
// sharp edges, with the boss deposited on top, does.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

#include "geometry/shapes.hpp"
#include "planner/atoms/check.hpp"
#include "planner/primitives/shapes.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using namespace hybridctl::geometry;
using testing::make_problem;
using testing::VoxelPrimitive;
using testing::VoxelProblem;

const Lattice kLattice{1.0, {0, 0, 0}};
const IndexBox kDomain{{0, 0, 0}, {80, 80, 50}};
constexpr double kTolerance = 1.0;  // mm
constexpr double kRadius = 8.0;     // bead and ball-mill radius, mm

// A 60 x 60 x 12 base (sharp outer edges and corners) carrying a domed boss of radius 12
// (no convex curvature sharper than the bead). Where the boss meets the base the part
// has a sharp concave edge all around.
Solid base() { return make_box(kLattice, {{10, 10, 4}, {70, 70, 16}}); }
Solid design() {
  const Solid boss = unite(make_cylinder(kLattice, Axis::Z, {40, 40, 16}, 12, 12), make_sphere(kLattice, {40, 40, 28}, 12));
  return unite(base(), boss);
}

Instrument bead() { return {{Ball{kRadius}}, {}}; }

// A ball-end mill from +Z on an endless shank: nothing in its shadow is reachable.
Instrument ball_mill() {
  AxialBody cutter{{Axis::Z, +1},
                   {{AxialSection::Kind::Sphere, 0, kRadius, kRadius, kRadius, 0},
                    {AxialSection::Kind::Cylinder, kRadius, 30, kRadius, 0, 0}}};
  AxialBody shank{{Axis::Z, +1},
                  {{AxialSection::Kind::Cylinder, 30, std::numeric_limits<double>::infinity(), kRadius, 0, 0}}};
  return {{cutter}, {shank}};
}

struct Primitives {
  VoxelPrimitive block, plate, uam, smmax;
};

const Primitives& primitives() {
  static const Primitives p = [] {
    const Solid d = design();
    return Primitives{
        {"block", Mode::Additive, true, 1.0, make_box(kLattice, {{6, 6, 4}, {74, 74, 44}})},
        // A near-net plate: stock up to the base's top face only.
        {"plate", Mode::Additive, true, 1.0, make_box(kLattice, {{6, 6, 4}, {74, 74, 16}})},
        {"U-AM", Mode::Additive, false, 2.0, additive_maximal(d, bead())},
        {"SM-max", Mode::Subtractive, false, 1.0, subtractive_maximal(d, ball_mill(), kDomain)},
    };
  }();
  return p;
}

Verdict verdict_of(const VoxelProblem& vp) { return check_manufacturability(vp.problem, vp.measures, kLattice); }

TEST(SharpCorners, DepositionAloneRoundsTheOuterCorners) {
  const VoxelProblem vp = make_problem({primitives().uam}, design(), kDomain, kTolerance);
  const Verdict v = verdict_of(vp);
  EXPECT_FALSE(v.manufacturable());
  EXPECT_TRUE(v.decided_without_search);
  // What is missing is the base's outer edges, deeper than the tolerance.
  const Solid missing = subtract(design(), primitives().uam.region);
  EXPECT_GT(farthest_distance(missing, complement(design(), kDomain)), kTolerance);
}

TEST(SharpCorners, MillingAloneLeavesAFilletInTheInnerCorner) {
  const auto& p = primitives();
  const VoxelProblem vp = make_problem({p.block, p.plate, p.smmax}, design(), kDomain, kTolerance);
  const Verdict v = verdict_of(vp);
  EXPECT_FALSE(v.manufacturable());
  ASSERT_FALSE(v.violations.empty());
  // The offending atom is the block's part that no removal reaches: it holds both the
  // boss and the fillet around its foot, which lies outside the design.
  const Solid left = subtract(p.block.region, p.smmax.region);
  const Solid fillet = subtract(left, design());
  EXPECT_GT(farthest_distance(fillet, design()), kTolerance);
  EXPECT_TRUE(find_plans(vp.problem).empty());
}

TEST(SharpCorners, AHybridPlanMakesBoth) {
  const auto& p = primitives();
  const VoxelProblem vp = make_problem({p.block, p.plate, p.uam, p.smmax}, design(), kDomain, kTolerance);
  const Verdict v = verdict_of(vp);
  EXPECT_TRUE(v.manufacturable()) << v.summary;
  EXPECT_EQ(v.modality, Modality::Hybrid);

  const auto plans = find_plans(vp.problem);
  ASSERT_FALSE(plans.empty());
  for (const Plan& plan : plans) {
    // Mill the plate to its sharp edges and deposit the boss, in either order.
    std::vector<std::string> names;
    for (const auto& step : plan.steps) names.push_back(vp.primitives[std::size_t(step.primitive)].name);
    EXPECT_EQ(names.front(), "plate") << expression(vp.problem, plan);
    EXPECT_NE(std::find(names.begin(), names.end(), "U-AM"), names.end()) << expression(vp.problem, plan);
    EXPECT_NE(std::find(names.begin(), names.end(), "SM-max"), names.end()) << expression(vp.problem, plan);

    // On the voxels: everything deeper than the tolerance inside the design is there,
    // nothing farther than the tolerance outside it.
    const Solid made = testing::evaluate(vp, plan);
    const ToleranceZone zone = make_tolerance_zone(design(), kTolerance);
    EXPECT_TRUE(subtract(zone.core, made).empty()) << expression(vp.problem, plan);
    EXPECT_TRUE(subtract(made, zone.hull).empty()) << expression(vp.problem, plan);
  }
}

}  // namespace
}  // namespace hybridctl::planner
