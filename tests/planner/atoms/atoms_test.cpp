// Atoms: the partition by membership codes, built incrementally or all at once, and
// their classes against the design's tolerance zone.

#include <gtest/gtest.h>

#include <random>

#include "geometry/shapes.hpp"
#include "planner/atoms/atoms.hpp"
#include "plan/deviation.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using geometry::Box3;
using geometry::make_box;
using geometry::make_sphere;

const Lattice kLattice{1.0, {0, 0, 0}};
const IndexBox kDomain{{0, 0, 0}, {20, 16, 10}};

std::vector<Solid> random_primitives(std::mt19937& rng, int n) {
  std::vector<Solid> out;
  std::uniform_real_distribution<double> at(0, 16), size(2, 10);
  for (int i = 0; i < n; ++i) {
    const double x = at(rng), y = at(rng), z = at(rng) / 2;
    if (i % 3 == 2) {
      out.push_back(make_sphere(kLattice, {x, y, z}, size(rng) / 2));
    } else {
      out.push_back(make_box(kLattice, {{x, y, z}, {x + size(rng), y + size(rng), z + size(rng) / 2}}));
    }
  }
  return out;
}

TEST(Atoms, WithoutPrimitivesTheDomainIsOneAtom) {
  AtomDecomposition atoms(kLattice, kDomain);
  EXPECT_EQ(atoms.atom_count(), 1);
  EXPECT_EQ(atoms.atom_solid(0).voxel_count(), kDomain.voxel_count());
}

TEST(Atoms, TwoOverlappingBoxesMakeFourAtoms) {
  AtomDecomposition atoms(kLattice, kDomain);
  atoms.add_primitive(make_box(kLattice, {{0, 0, 0}, {10, 10, 5}}));
  atoms.add_primitive(make_box(kLattice, {{5, 5, 0}, {15, 15, 5}}));
  ASSERT_EQ(atoms.atom_count(), 4);
  EXPECT_EQ(atoms.code(atoms.atom_at({7, 7, 2})).bits(2), "11");
  EXPECT_EQ(atoms.code(atoms.atom_at({1, 1, 2})).bits(2), "10");
  EXPECT_EQ(atoms.code(atoms.atom_at({12, 12, 2})).bits(2), "01");
  EXPECT_EQ(atoms.code(atoms.atom_at({19, 0, 9})).bits(2), "00");
  EXPECT_EQ(atoms.atom_solid(atoms.atom_at({7, 7, 2})).voxel_count(), 5 * 5 * 5);
}

TEST(Atoms, APrimitiveContainingAWholeAtomRelabelsItWithoutSplitting) {
  AtomDecomposition atoms(kLattice, kDomain);
  atoms.add_primitive(make_box(kLattice, {{2, 2, 2}, {4, 4, 4}}));
  atoms.add_primitive(make_box(kLattice, {{0, 0, 0}, {8, 8, 8}}));
  EXPECT_EQ(atoms.atom_count(), 3);  // "00", "01", "11"; no "10"
  EXPECT_EQ(atoms.code(atoms.atom_at({3, 3, 3})).bits(2), "11");
}

TEST(Atoms, IncrementalSplittingEqualsRecompute) {
  std::mt19937 rng(42);
  for (int trial = 0; trial < 10; ++trial) {
    const auto prims = random_primitives(rng, 3 + trial % 6);
    AtomDecomposition incremental(kLattice, kDomain);
    std::vector<const Solid*> pointers;
    for (const Solid& p : prims) {
      incremental.add_primitive(p);
      pointers.push_back(&p);
      EXPECT_TRUE(same_partition(incremental, AtomDecomposition::recompute(kLattice, kDomain, pointers)));
    }
  }
}

TEST(Atoms, CodesBeyondSixtyFourPrimitivesWork) {
  AtomDecomposition atoms(kLattice, kDomain);
  std::vector<Solid> prims;
  for (int i = 0; i < 70; ++i) prims.push_back(make_box(kLattice, {{double(i % 20), 0, 0}, {double(i % 20) + 1, 16, 10}}));
  std::vector<const Solid*> pointers;
  for (const Solid& p : prims) {
    atoms.add_primitive(p);
    pointers.push_back(&p);
  }
  EXPECT_TRUE(same_partition(atoms, AtomDecomposition::recompute(kLattice, kDomain, pointers)));
  const AtomSet& c = atoms.code(atoms.atom_at({5, 0, 0}));
  EXPECT_TRUE(c.test(5));
  EXPECT_TRUE(c.test(25));
  EXPECT_TRUE(c.test(45));
  EXPECT_TRUE(c.test(65));
  EXPECT_FALSE(c.test(66));
}

TEST(Atoms, ClassesFollowTheToleranceZone) {
  const Lattice fine{0.5, {0, 0, 0}};
  const IndexBox domain{{0, 0, 0}, {40, 40, 20}};
  const Solid design = make_box(fine, {{5, 5, 2}, {15, 15, 8}});
  AtomDecomposition atoms(fine, domain);
  atoms.add_primitive(make_box(fine, {{5, 5, 2}, {15, 15, 8}}));          // exactly the design
  atoms.add_primitive(make_box(fine, {{4.5, 5, 2}, {15, 15, 8}}));        // half a mm too wide: a band sliver
  atoms.add_primitive(make_box(fine, {{10, 5, 2}, {19, 15, 8}}));         // sticks far out
  const auto m = measure_atoms(atoms, design, make_tolerance_zone(design, 1.0), 0.0);
  auto class_at = [&](Index3 v) { return m[std::size_t(atoms.atom_at(v))].atom_class; };
  EXPECT_EQ(class_at({12, 12, 8}), AtomClass::MustIn);    // "110": design, left of x = 10
  EXPECT_EQ(class_at({9, 12, 8}), AtomClass::Free);       // "010": the 0.5 mm band at x 4.5..5
  EXPECT_EQ(class_at({35, 12, 8}), AtomClass::MustOut);   // "001": x 15..19 beyond the band
  EXPECT_EQ(class_at({0, 0, 0}), AtomClass::MustOut);     // outside everything
  const auto& in = m[std::size_t(atoms.atom_at({12, 12, 8}))];
  EXPECT_DOUBLE_EQ(in.volume, 5 * 10 * 6);
  EXPECT_NEAR(in.centroid.x, 7.5, 1e-9);
  EXPECT_NEAR(in.centroid.y, 10, 1e-9);
}

TEST(Atoms, AnAtomStraddlingTheDesignBeyondToleranceIsViolating) {
  const Lattice fine{0.5, {0, 0, 0}};
  const IndexBox domain{{0, 0, 0}, {40, 40, 20}};
  const Solid design = make_box(fine, {{5, 5, 2}, {15, 15, 8}});
  AtomDecomposition atoms(fine, domain);
  atoms.add_primitive(make_box(fine, {{2, 5, 2}, {15, 15, 8}}));  // 3 mm too wide
  const auto m = measure_atoms(atoms, design, make_tolerance_zone(design, 1.0), 0.0);
  EXPECT_EQ(m[std::size_t(atoms.atom_at({12, 12, 8}))].atom_class, AtomClass::Violating);
  // As a sliver it would be noise.
  const auto lenient = measure_atoms(atoms, design, make_tolerance_zone(design, 1.0), 1e6);
  EXPECT_EQ(lenient[std::size_t(atoms.atom_at({12, 12, 8}))].atom_class, AtomClass::Free);
}

// Thin features and gaps (planner/atoms/tolerance_zone.hpp). A plate with a fin one voxel
// thick, from two depositions: the fin has no core, so with the core and hull alone its
// atom was free and the plate alone a goal, 12 voxels short at the fin's tip.
TEST(Atoms, AThinFinIsMustInSoAPlanWithoutItIsNoGoal) {
  const IndexBox domain{{0, 0, 0}, {32, 32, 24}};
  const Solid plate = make_box(kLattice, {{4, 4, 2}, {28, 28, 5}}), fin = make_box(kLattice, {{14, 6, 5}, {15, 26, 17}});
  const Solid design = unite(plate, fin);
  const auto vp = testing::make_problem(
      {{"plate", Mode::Additive, false, 1.0, plate}, {"fin", Mode::Additive, false, 5.0, fin}}, design, domain, 1.0);
  const int fin_atom = vp.atoms.atom_at({14, 10, 10});
  EXPECT_EQ(vp.measures[std::size_t(fin_atom)].atom_class, AtomClass::MustIn);
  const ToleranceZone zone = make_tolerance_zone(design, 1.0);
  const auto core_and_hull_only =
      measure_atoms(vp.atoms, design, {zone.core, zone.hull, Solid(kLattice, {}), Solid(kLattice, {})}, 0.0);
  EXPECT_EQ(core_and_hull_only[std::size_t(fin_atom)].atom_class, AtomClass::Free);
  EXPECT_FALSE(is_goal(vp.problem, vp.problem.primitives[0].atoms));
  const std::vector<Plan> plans = find_plans(vp.problem);
  ASSERT_FALSE(plans.empty());
  for (const Plan& plan : plans) {
    const Solid made = testing::evaluate(vp, plan);
    EXPECT_TRUE(subtract(fin, made).empty()) << expression(vp.problem, plan);
    EXPECT_TRUE(plan::measure_deviation(made, design, domain, 1.0).within_tolerance) << expression(vp.problem, plan);
  }
}

// A block with a slot one voxel wide, from a stock and a removal: the slot lies wholly
// in the hull, so it was free and the stock alone a goal.
TEST(Atoms, ANarrowSlotIsMustOutSoAPlanThatFillsItIsNoGoal) {
  const IndexBox domain{{0, 0, 0}, {32, 32, 20}};
  const Solid block = make_box(kLattice, {{4, 4, 2}, {28, 28, 14}}), slot = make_box(kLattice, {{14, 4, 5}, {15, 28, 14}});
  const Solid design = subtract(block, slot);
  const auto vp = testing::make_problem(
      {{"stock", Mode::Additive, true, 0.0, block}, {"mill", Mode::Subtractive, false, 1.0, slot}}, design, domain, 1.0);
  EXPECT_EQ(vp.measures[std::size_t(vp.atoms.atom_at({14, 10, 10}))].atom_class, AtomClass::MustOut);
  EXPECT_FALSE(is_goal(vp.problem, vp.problem.primitives[0].atoms));
  const std::vector<Plan> plans = find_plans(vp.problem);
  ASSERT_FALSE(plans.empty());
  for (const Plan& plan : plans) {
    const Solid made = testing::evaluate(vp, plan);
    EXPECT_TRUE(intersect(slot, made).empty()) << expression(vp.problem, plan);
    EXPECT_TRUE(plan::measure_deviation(made, design, domain, 1.0).within_tolerance) << expression(vp.problem, plan);
  }
}

}  // namespace
}  // namespace hybridctl::planner
