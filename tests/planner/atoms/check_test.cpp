// The manufacturability check: a verdict before search, decided outright for unimodal
// primitive sets, with every offending atom located and described.

#include <gtest/gtest.h>

#include "planner/atoms/check.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using geometry::make_box;
using testing::make_problem;
using testing::VoxelPrimitive;

const Lattice kUnit{1.0, {0, 0, 0}};
const IndexBox kDomain{{0, 0, 0}, {20, 10, 4}};

Solid box(double x0, double x1) { return make_box(kUnit, {{x0, 0, 0}, {x1, 10, 4}}); }

Verdict verdict_of(std::vector<VoxelPrimitive> prims, const Solid& design) {
  const auto vp = make_problem(std::move(prims), design, kDomain);
  const auto measures = measure_atoms(vp.atoms, design, make_tolerance_zone(design, 0), 0);
  return check_manufacturability(vp.problem, measures, kUnit);
}

TEST(Check, AdditiveOnlySetsAreDecidedWithoutSearch) {
  const Solid design = box(2, 12);
  const Verdict yes = verdict_of({{"A", Mode::Additive, false, 1, box(2, 8)}, {"B", Mode::Additive, false, 1, box(6, 12)}}, design);
  EXPECT_TRUE(yes.manufacturable());
  EXPECT_TRUE(yes.decided_without_search);
  EXPECT_EQ(yes.modality, Modality::AdditiveOnly);
  // B overfills past x = 12 and A alone is short: no union of clean depositions works.
  const Verdict no = verdict_of({{"A", Mode::Additive, false, 1, box(2, 8)}, {"B", Mode::Additive, false, 1, box(6, 14)}}, design);
  EXPECT_FALSE(no.manufacturable());
  EXPECT_TRUE(no.decided_without_search);
}

TEST(Check, StockAndRemovalsAreDecidedWithoutSearch) {
  const Solid design = box(2, 12);
  const Verdict yes = verdict_of({{"stock", Mode::Additive, true, 1, box(0, 20)},
                                  {"left", Mode::Subtractive, false, 1, box(0, 2)},
                                  {"right", Mode::Subtractive, false, 1, box(12, 20)}},
                                 design);
  EXPECT_EQ(yes.modality, Modality::SubtractiveOnly);
  EXPECT_TRUE(yes.manufacturable());
  const Verdict no = verdict_of({{"stock", Mode::Additive, true, 1, box(0, 20)}, {"left", Mode::Subtractive, false, 1, box(0, 2)}},
                                design);
  EXPECT_FALSE(no.manufacturable());
}

TEST(Check, AStraddlingAtomIsLocatedAndDescribed) {
  const Solid design = box(2, 12);
  // The stock's part x in [12, 15) is outside the design but no removal reaches it
  // without also... here simply: one atom, the stock minus the cut, straddles x = 12.
  const Verdict v = verdict_of({{"stock", Mode::Additive, true, 1, box(0, 15)}, {"cut", Mode::Subtractive, false, 1, box(0, 2)}},
                               design);
  EXPECT_FALSE(v.manufacturable());
  EXPECT_TRUE(v.decided_without_search);
  ASSERT_EQ(v.violations.size(), 1u);
  const ViolatingAtom& a = v.violations[0];
  EXPECT_EQ(a.code, "10");
  EXPECT_EQ(a.primitives, std::vector<int>{0});
  EXPECT_DOUBLE_EQ(a.volume, 13 * 10 * 4);
  EXPECT_DOUBLE_EQ(a.volume_in_design, 10 * 10 * 4);
  EXPECT_DOUBLE_EQ(a.bounds.min.x, 2);
  EXPECT_DOUBLE_EQ(a.bounds.max.x, 15);
  EXPECT_NEAR(a.centroid.x, 8.5, 1e-9);
  EXPECT_NE(a.description.find("520 mm\u00B3 region around (8.5, 5.0, 2.0) mm"), std::string::npos) << a.description;
  EXPECT_NE(a.description.find("no removal reaches it"), std::string::npos) << a.description;
}

TEST(Check, HybridSetsWithoutViolationsGoToTheSearch) {
  const Solid design = box(2, 12);
  const Verdict v = verdict_of({{"stock", Mode::Additive, true, 1, box(0, 10)},
                                {"cut", Mode::Subtractive, false, 1, box(0, 2)},
                                {"add", Mode::Additive, false, 1, box(8, 12)}},
                               design);
  EXPECT_EQ(v.modality, Modality::Hybrid);
  EXPECT_TRUE(v.manufacturable());
  EXPECT_FALSE(v.decided_without_search);
  EXPECT_TRUE(v.violations.empty());
}

// A fin one voxel thick that only a deposition three voxels too wide reaches: its atom
// holds the fin (thinner than twice the tolerance) and air beyond the hull.
TEST(Check, AThinFeatureOnlyAnOverfillReachesIsAViolationThatSaysSo) {
  const IndexBox domain{{0, 0, 0}, {32, 32, 24}};
  const Solid plate = make_box(kUnit, {{4, 4, 2}, {28, 28, 5}}), fin = make_box(kUnit, {{14, 6, 5}, {15, 26, 17}});
  const Solid wide = make_box(kUnit, {{11, 6, 5}, {18, 26, 17}});
  const Solid design = unite(plate, fin);
  const auto vp = make_problem({{"plate", Mode::Additive, false, 1.0, plate}, {"wide", Mode::Additive, false, 1.0, wide}},
                               design, domain, 1.0);
  const Verdict v = check_manufacturability(vp.problem, vp.measures, kUnit);
  EXPECT_FALSE(v.manufacturable());
  ASSERT_EQ(v.violations.size(), 1u);
  EXPECT_TRUE(v.violations[0].holds_thin_feature);
  EXPECT_TRUE(v.violations[0].beyond_hull);
  EXPECT_FALSE(v.violations[0].holds_core);
  EXPECT_NE(v.violations[0].description.find("a feature thinner than twice the tolerance needs it"), std::string::npos)
      << v.violations[0].description;
}

}  // namespace
}  // namespace hybridctl::planner

namespace hybridctl::planner {
namespace {

// A design atom is made by the last deposit that holds it, and no removal that holds it
// may follow: what that deposit lays outside the design must be cleared by removals that
// spare the atom. Here the one deposit overfills past x = 12, and the one removal that
// reaches the overfill also cuts the design's last 2 mm: that strip is never made. (A
// second deposit of the overfill alone splits the atoms at the design's face.)
TEST(Check, ADesignAtomThatEveryDepositLeavesOnlyForRemovalsCuttingIntoItIsRefusedWithoutSearch) {
  const Solid design = box(2, 12);
  const Verdict no = verdict_of({{"deposit", Mode::Additive, false, 1, box(2, 14)},
                                 {"spill", Mode::Additive, false, 1, box(12, 14)},
                                 {"trim", Mode::Subtractive, false, 1, box(0, 2)},
                                 {"cut", Mode::Subtractive, false, 1, box(10, 20)}},
                                design);
  EXPECT_FALSE(no.manufacturable());
  EXPECT_TRUE(no.decided_without_search);
  ASSERT_EQ(no.violations.size(), 1u);
  EXPECT_NEAR(no.violations[0].centroid.x, 11.0, 1e-9);
  EXPECT_DOUBLE_EQ(no.violations[0].volume, 80.0);
  EXPECT_NE(no.violations[0].description.find("every deposit that holds it (1) also lays material outside the design"),
            std::string::npos)
      << no.violations[0].description;
  EXPECT_NE(no.violations[0].description.find("deposit leaves 80 mm\u00B3 around (13.0, 5.0, 2.0) mm"), std::string::npos)
      << no.violations[0].description;
  // A removal that clears the overfill and spares the strip: the search decides.
  const Verdict yes = verdict_of({{"deposit", Mode::Additive, false, 1, box(2, 14)},
                                  {"spill", Mode::Additive, false, 1, box(12, 14)},
                                  {"trim", Mode::Subtractive, false, 1, box(0, 2)},
                                  {"cut", Mode::Subtractive, false, 1, box(10, 20)},
                                  {"finish", Mode::Subtractive, false, 1, box(12, 20)}},
                                 design);
  EXPECT_TRUE(yes.manufacturable());
  EXPECT_FALSE(yes.decided_without_search);
  EXPECT_TRUE(yes.violations.empty());
}

// A proof's verdict names first the air a raw stock holds that every removal reaching it
// cuts design with it, and says so: a channel under a lid, cleared only through the lid,
// which no deposit lays again over the channel (laid first, on the plate, it would lack
// the wall). Then the design around it, the largest first.
TEST(Check, AProofsVerdictNamesFirstTheAirOnlyACutIntoTheDesignClears) {
  enum { Lid, Channel, Wall, Atoms };
  PlanningProblem p;
  p.atoms = {{20, true, false}, {30, false, true}, {100, true, false}};
  const auto primitive = [](std::string name, Mode mode, std::initializer_list<int> held) {
    PrimitiveSpec s;
    s.name = std::move(name);
    s.mode = mode;
    s.atoms = AtomSet(Atoms);
    for (int a : held) s.atoms.set(a);
    return s;
  };
  p.primitives = {primitive("P1", Mode::Additive, {Lid, Channel, Wall}), primitive("P2", Mode::Subtractive, {Lid, Channel}),
                  primitive("P3", Mode::Additive, {Lid})};
  p.primitives[0].raw_stock = true;
  auto footing = std::make_shared<DepositFooting>();
  footing->kind = {DepositFooting::NeedsCarrier, DepositFooting::OnPlate, DepositFooting::OnPlate};
  std::vector<AtomSet> carriers(Atoms, AtomSet(Atoms));
  carriers[Lid].set(Channel);
  footing->carriers = AtomRelation(std::move(carriers));
  p.primitives[2].footing = footing;
  std::vector<AtomMeasures> measures(Atoms);
  const Vec3 centroids[Atoms] = {{25, 15, 22}, {25, 15, 16}, {25, 5, 10}};
  for (int a = 0; a < Atoms; ++a) {
    measures[std::size_t(a)].code = AtomSet(int(p.primitives.size()));
    for (int i = 0; i < int(p.primitives.size()); ++i) measures[std::size_t(a)].code.set(i, p.primitives[std::size_t(i)].atoms.test(a));
    measures[std::size_t(a)].volume = p.atoms[std::size_t(a)].volume;
    measures[std::size_t(a)].centroid = centroids[a];
  }
  const CoreProof proof = prove_by_core(p);
  ASSERT_EQ(proof.outcome, CoreProof::Outcome::Proven);
  const Verdict v = core_verdict(p, proof, measures, kUnit);
  ASSERT_EQ(v.violations.size(), 3u);
  EXPECT_EQ(v.violations[0].atom, int(Channel));
  EXPECT_NE(v.violations[0].description.find("(must be left empty), in P1, P2; no removal reaches it without cutting the design"),
            std::string::npos)
      << v.violations[0].description;
  EXPECT_EQ(v.violations[1].atom, int(Wall));
  EXPECT_EQ(v.violations[2].atom, int(Lid));
  for (std::size_t i = 1; i < 3; ++i)
    EXPECT_EQ(v.violations[i].description.find("without cutting"), std::string::npos) << v.violations[i].description;
  EXPECT_NE(v.summary.find("At its heart, air that a raw stock holds and no removal clears without cutting the design, "
                           "which would then have to be made again: a 30 mm\u00B3 region around (25.0, 15.0, 16.0) mm"),
            std::string::npos)
      << v.summary;
}

}  // namespace
}  // namespace hybridctl::planner
