// A proof that no plan exists from a few atoms (planner/search/core_proof.hpp, docs/search.md):
// sound against the exhaustive exploration, and able to see what no single atom shows.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>

#include "planner/atoms/check.hpp"
#include "planner/search/core_proof.hpp"
#include "planner/search/steps.hpp"

namespace hybridctl::planner {
namespace {

PrimitiveSpec primitive(std::string name, Mode mode, int atoms, std::initializer_list<int> held) {
  PrimitiveSpec s;
  s.name = std::move(name);
  s.mode = mode;
  s.atoms = AtomSet(atoms);
  for (int a : held) s.atoms.set(a);
  s.tool = mode == Mode::Additive ? "head" : "T1";
  return s;
}

// Per atom of `atoms`, the set of `members` (the same for each listed atom).
AtomRelation relation(int atoms, std::initializer_list<int> of, std::initializer_list<int> members) {
  std::vector<AtomSet> sets(std::size_t(atoms), AtomSet{atoms});
  for (int a : of)
    for (int m : members) sets[std::size_t(a)].set(m);
  return AtomRelation(std::move(sets));
}

// A closed channel: a floor F, a roof R over the channel C. Each atom alone can be put
// right, and a last deposit of F and R lays nothing that cannot be cleared; but the roof's
// deposit needs something under it (only C carries it), the floor's is out of reach under
// the roof, and cutting the channel open cuts the roof.
struct Channel {
  enum { F, R, C, Atoms };
  PlanningProblem p;
  Channel(bool floor_blocked_by_roof) {
    p.atoms = {{100, true, false}, {20, true, false}, {30, false, true}};
    p.max_uses = 3;
    p.primitives = {primitive("floor", Mode::Additive, Atoms, {F}), primitive("roof", Mode::Additive, Atoms, {R}),
                    primitive("all", Mode::Additive, Atoms, {F, R, C}), primitive("cut", Mode::Subtractive, Atoms, {R, C})};
    if (floor_blocked_by_roof) p.primitives[0].blocked_by = std::make_shared<const AtomRelation>(relation(Atoms, {F}, {R}));
    auto footing = std::make_shared<DepositFooting>();
    footing->kind = {DepositFooting::OnPlate, DepositFooting::NeedsCarrier, DepositFooting::OnPlate};
    footing->carriers = relation(Atoms, {R}, {C});
    p.primitives[1].footing = footing;
  }
};

TEST(CoreProof, AClosedChannelIsProvenImpossibleFromItsThreeAtoms) {
  const Channel channel(true);
  const CoreProof proof = prove_by_core(channel.p);
  ASSERT_EQ(proof.outcome, CoreProof::Outcome::Proven);
  EXPECT_EQ(proof.core, (std::vector<int>{Channel::F, Channel::R, Channel::C}));
  const Reachability reach = explore_reachable(channel.p);
  EXPECT_TRUE(reach.complete);
  EXPECT_FALSE(reach.goal);
  // The check before the search sees nothing wrong with any one atom.
  std::vector<AtomMeasures> measures(3);
  EXPECT_TRUE(check_manufacturability(channel.p, measures, Lattice{}).manufacturable());
}

TEST(CoreProof, WhenTheRoofDoesNotBlockTheFloorTheReplayedPlanMakesThePart) {
  const Channel channel(false);
  const CoreProof proof = prove_by_core(channel.p);
  ASSERT_EQ(proof.outcome, CoreProof::Outcome::Feasible);
  Plan plan;
  ASSERT_TRUE(simulate(channel.p, proof.sequence, plan));
  EXPECT_TRUE(is_goal(channel.p, plan.final_state));
  EXPECT_EQ(expression(channel.p, plan), "(roof \u222A floor)");
}

// A floor F and a roof R laid together, the roof on a filler C that only a deposit with a
// stud S lays, and the only way to clear C takes the floor with it: whatever the order,
// the floor is laid twice. With each primitive allowed once the proof cannot call that a
// plan, and says how many uses it needs.
TEST(CoreProof, AReplayThatNeedsAPrimitiveTwiceIsNoPlanButSaysHowManyUsesItNeeds) {
  enum { F, R, S, C, Atoms };
  PlanningProblem p;
  p.atoms = {{100, true, false}, {20, true, false}, {10, true, false}, {30, false, true}};
  p.max_uses = 1;
  p.primitives = {primitive("fill", Mode::Additive, Atoms, {C, S}), primitive("lay", Mode::Additive, Atoms, {F, R}),
                  primitive("cut", Mode::Subtractive, Atoms, {F, C})};
  auto footing = std::make_shared<DepositFooting>();
  footing->kind = {DepositFooting::OnPlate, DepositFooting::NeedsCarrier, DepositFooting::None, DepositFooting::None};
  footing->carriers = relation(Atoms, {R}, {C});
  p.primitives[1].footing = footing;
  CoreProof proof = prove_by_core(p);
  EXPECT_EQ(proof.outcome, CoreProof::Outcome::Unknown);
  EXPECT_EQ(proof.reuse_needed, 2);
  EXPECT_EQ(std::count(proof.sequence.begin(), proof.sequence.end(), 1), 2);
  p.max_uses = 2;
  proof = prove_by_core(p);
  ASSERT_EQ(proof.outcome, CoreProof::Outcome::Feasible);
  EXPECT_EQ(proof.reuse_needed, 0);
  Plan plan;
  ASSERT_TRUE(simulate(p, proof.sequence, plan));
  EXPECT_TRUE(is_goal(p, plan.final_state));
}

// The roof R rests on either of C1 and C2, and the head cannot reach it past C1, which must
// go. Milling both away first leaves the roof on nothing: the proof learns that its
// carriers are a group, one bit in the projection. A removal of C1 alone leaves C2 to carry
// it, so the group's bit stays set, and the plan that does so is found, not ruled out.
TEST(CoreProof, ACarrierGroupStaysSetWhileOneOfItsAtomsRemains) {
  enum { R, C1, C2, Atoms };
  PlanningProblem p;
  p.atoms = {{50, true, false}, {10, false, true}, {10, false, false}};
  p.start_from_stock = true;
  p.primitives = {primitive("stock", Mode::Additive, Atoms, {C1, C2}), primitive("both", Mode::Subtractive, Atoms, {C1, C2}),
                  primitive("one", Mode::Subtractive, Atoms, {C1}), primitive("roof", Mode::Additive, Atoms, {R})};
  p.primitives[0].raw_stock = true;
  p.primitives[3].blocked_by = std::make_shared<const AtomRelation>(relation(Atoms, {R}, {C1}));
  auto footing = std::make_shared<DepositFooting>();
  footing->kind = {DepositFooting::NeedsCarrier, DepositFooting::OnPlate, DepositFooting::OnPlate};
  footing->carriers = relation(Atoms, {R}, {C1, C2});
  p.primitives[3].footing = footing;
  const CoreProof proof = prove_by_core(p);
  ASSERT_EQ(proof.outcome, CoreProof::Outcome::Feasible);
  Plan plan;
  ASSERT_TRUE(simulate(p, proof.sequence, plan));
  EXPECT_EQ(expression(p, plan), "((stock \u2212 one) \u222A roof)");
  EXPECT_EQ(proof.joined[int(CoreProof::Why::NothingUnder)], 1);  // the group, not C2
}

// The budget of projected states is a limit, not a verdict.
TEST(CoreProof, AProofThatDoesNotFitItsBudgetSaysUnknown) {
  const Channel channel(true);
  CoreProofLimits limits;
  limits.max_states = 2;
  EXPECT_EQ(prove_by_core(channel.p, limits).outcome, CoreProof::Outcome::Unknown);
}

// A random instance with reach and footing, more atoms than primitives; with a raw stock
// on odd trials.
PlanningProblem random_instance(std::mt19937& rng, int trial) {
  const int atoms = 4 + int(rng() % 9), n = 4 + int(rng() % 7);
  PlanningProblem p;
  p.max_uses = 8;
  p.start_from_stock = trial % 2 == 1;
  for (int a = 0; a < atoms; ++a) {
    const unsigned c = rng() % 5;  // must-in 2 in 5, must-out 1 in 5
    p.atoms.push_back({1.0 + rng() % 10, c < 2, c == 2});
  }
  for (int i = 0; i < n; ++i) {
    PrimitiveSpec s = primitive("P" + std::to_string(i), i == 0 || rng() % 3 ? Mode::Additive : Mode::Subtractive, atoms, {});
    for (int a = 0; a < atoms; ++a)
      if (rng() % 2 || (i == 0 && p.start_from_stock)) s.atoms.set(a);
    s.raw_stock = i == 0 && p.start_from_stock;  // then every later deposit needs footing
    if (s.mode == Mode::Additive && rng() % 2) {
      std::vector<AtomSet> over(std::size_t(atoms), AtomSet{atoms});
      for (auto& o : over)
        if (rng() % 3 == 0) o.set(int(rng() % unsigned(atoms)));
      s.blocked_by = std::make_shared<const AtomRelation>(std::move(over));
    }
    if (s.mode == Mode::Additive && rng() % 2) {
      auto footing = std::make_shared<DepositFooting>();
      std::vector<AtomSet> carriers;
      for (int a = 0; a < atoms; ++a) {
        footing->kind.push_back(rng() % 3 == 0 ? DepositFooting::NeedsCarrier : DepositFooting::OnPlate);
        carriers.emplace_back(atoms);
        for (int k = 0, m = 1 + int(rng() % 4); k < m; ++k) carriers.back().set(int(rng() % unsigned(atoms)));
      }
      footing->carriers = AtomRelation(std::move(carriers));
      s.footing = footing;
    }
    p.primitives.push_back(std::move(s));
  }
  return p;
}

// Random instances with reach and footing, more atoms than primitives: every proof is
// confirmed by the complete exploration of the whole problem, and every plan found makes
// the part.
TEST(CoreProof, AgreesWithTheExhaustiveExplorationOnRandomInstances) {
  std::mt19937 rng(2024);
  int proven = 0, feasible = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const PlanningProblem p = random_instance(rng, trial);
    const Reachability reach = explore_reachable(p, 1'000'000);
    ASSERT_TRUE(reach.goal || reach.complete) << "trial " << trial;
    const CoreProof proof = prove_by_core(p);
    ASSERT_NE(proof.outcome, CoreProof::Outcome::Unknown) << "trial " << trial;
    if (proof.outcome == CoreProof::Outcome::Proven) {
      ++proven;
      EXPECT_FALSE(reach.goal) << "trial " << trial;
    } else {
      ++feasible;
      Plan plan;
      EXPECT_TRUE(simulate(p, proof.sequence, plan) && is_goal(p, plan.final_state)) << "trial " << trial;
      EXPECT_TRUE(reach.goal) << "trial " << trial;
    }
  }
  EXPECT_GT(proven, 40);
  EXPECT_GT(feasible, 40);
}


// A proof names the atoms it needs and no others: S as the refinement leaves it also holds
// atoms that refuted only an earlier projected plan (on the gusset bracket, rows of voxels
// along the bottom edges, named as if they were the reason), and each of those is dropped
// again. Without any one atom of a proof, the projection has a plan.
TEST(CoreProof, EveryAtomOfAProofIsNeededByIt) {
  std::mt19937 rng(2024);
  int proven = 0, smaller = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const PlanningProblem p = random_instance(rng, trial);
    const CoreProof proof = prove_by_core(p);
    if (proof.outcome != CoreProof::Outcome::Proven) continue;
    ++proven;
    smaller += proof.found > int(proof.core.size());
    EXPECT_TRUE(projection_refutes(p, proof.core, proof.groups)) << "trial " << trial;
    for (std::size_t k = 0; k < proof.core.size() && proof.core.size() > 1; ++k) {
      std::vector<int> less = proof.core;
      less.erase(less.begin() + std::ptrdiff_t(k));
      EXPECT_FALSE(projection_refutes(p, less, proof.groups)) << "trial " << trial << ", atom " << proof.core[k];
    }
  }
  EXPECT_GT(proven, 40);
  EXPECT_GT(smaller, 5);  // the refinement's S is often larger than the proof needs
}

// Air that a raw stock holds and that every removal reaching it cuts design with it: a
// closed channel. The proof's verdict names it first.
TEST(CoreProof, AirThatOnlyACutIntoTheDesignClearsIsTold) {
  enum { Lid, Channel, Outside, Atoms };
  PlanningProblem p;
  p.atoms = {{20, true, false}, {30, false, true}, {40, false, true}};
  p.primitives = {primitive("stock", Mode::Additive, Atoms, {Lid, Channel, Outside}),
                  primitive("through the lid", Mode::Subtractive, Atoms, {Lid, Channel}),
                  primitive("around", Mode::Subtractive, Atoms, {Outside}),
                  primitive("deposit", Mode::Additive, Atoms, {Lid})};
  p.primitives[0].raw_stock = true;
  EXPECT_TRUE(cleared_only_by_cutting(p, Channel));
  EXPECT_FALSE(cleared_only_by_cutting(p, Outside));  // a removal clears it alone
  EXPECT_FALSE(cleared_only_by_cutting(p, Lid));       // design
  // Air no stock holds is there only if a deposit lays it: no such thing to clear.
  p.primitives[0].atoms.set(Channel, false);
  EXPECT_FALSE(cleared_only_by_cutting(p, Channel));
}
}  // namespace
}  // namespace hybridctl::planner
