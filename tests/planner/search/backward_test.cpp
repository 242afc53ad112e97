// The plan search's reductions and its backward direction (docs/search.md), each against
// the exhaustive enumerator on instances made to defeat it.

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "planner/search/reduce.hpp"

namespace hybridctl::planner {
namespace {

PrimitiveSpec primitive(std::string name, Mode mode, double cost, int atoms, std::initializer_list<int> held,
                        bool raw = false) {
  PrimitiveSpec s;
  s.name = std::move(name);
  s.mode = mode;
  s.raw_stock = raw;
  s.cost_per_mm3 = cost;
  s.atoms = AtomSet(atoms);
  for (int a : held) s.atoms.set(a);
  s.tool = raw ? "stock" : "T1";
  return s;
}

// A random symbolic instance: atoms of three classes, primitives over them, and for some
// deposits a reach that material present blocks and a footing that needs a carrier.
PlanningProblem random_problem(std::mt19937& rng, int n) {
  const int atoms = 3 + int(rng() % 6);
  PlanningProblem p;
  std::uniform_real_distribution<double> volume(1, 20), cost(0.2, 3.0);
  for (int a = 0; a < atoms; ++a) {
    const unsigned c = rng() % 5;  // must-in twice as often as the others
    p.atoms.push_back({volume(rng), c < 2, c == 2 || c == 3});
  }
  for (int i = 0; i < n; ++i) {
    PrimitiveSpec s = primitive("P" + std::to_string(i), i == 0 || rng() % 2 ? Mode::Additive : Mode::Subtractive,
                                cost(rng), atoms, {});
    for (int a = 0; a < atoms; ++a)
      if (rng() % 2) s.atoms.set(a);
    s.tool = "T" + std::to_string(rng() % 2);
    if (s.mode == Mode::Additive && rng() % 3 == 0) {
      std::vector<AtomSet> reach(std::size_t(atoms), AtomSet{atoms});
      for (auto& over : reach)
        if (rng() % 3 == 0) over.set(int(rng() % unsigned(atoms)));
      s.blocked_by = std::make_shared<const AtomRelation>(std::move(reach));
    }
    if (s.mode == Mode::Additive && rng() % 3 == 0) {
      auto footing = std::make_shared<DepositFooting>();
      std::vector<AtomSet> carriers;
      for (int a = 0; a < atoms; ++a) {
        footing->kind.push_back(rng() % 3 == 0 ? DepositFooting::NeedsCarrier : DepositFooting::OnPlate);
        carriers.emplace_back(atoms);
        carriers.back().set(int(rng() % unsigned(atoms)));
      }
      footing->carriers = AtomRelation(std::move(carriers));
      s.footing = footing;
    }
    p.primitives.push_back(std::move(s));
  }
  return p;
}

void expect_same_plans(const std::vector<Plan>& found, const std::vector<Plan>& oracle, std::size_t k, int trial) {
  ASSERT_EQ(found.size(), std::min(k, oracle.size())) << "trial " << trial;
  for (std::size_t i = 0; i < found.size(); ++i)
    EXPECT_NEAR(found[i].cost, oracle[i].cost, 1e-9 * std::max(1.0, oracle[i].cost)) << "trial " << trial << " plan " << i;
}

// Reach and footing depend on the material present before an action, which a backward
// search only knows of whole plans; merged atoms must keep what blocks each apart.
TEST(SearchReductions, EveryDirectionWithAndWithoutReductionAgreesWithTheOracleUnderReachAndFooting) {
  std::mt19937 rng(1515);
  int solvable = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 6;
    PlanningProblem p = random_problem(rng, n);
    p.max_uses = n <= 4 && trial % 5 == 0 ? 2 : 1;
    const auto oracle = enumerate_plans(p);
    solvable += !oracle.empty();
    for (SearchDirection direction : {SearchDirection::Forward, SearchDirection::Backward})
      for (bool reduce : {false, true}) {
        SearchOptions options{4};
        options.direction = direction;
        options.reduce = reduce;
        expect_same_plans(find_plans(p, options), oracle, 4, trial);
      }
  }
  EXPECT_GT(solvable, 40);
}

// P2 deposits a must-out atom: no plan can end with it, but one can use it when a later
// removal takes that atom away; the reduction keeps it, and drops P3, which deposits a
// must-out atom nothing removes.
TEST(SearchReductions, APrimitiveThatGetsAnAtomWrongIsKeptWhenALaterOneCanDecideIt) {
  PlanningProblem p;
  p.atoms = {{10, true, false}, {10, true, false}, {1, false, true}, {1, false, true}};
  p.primitives = {primitive("P1", Mode::Additive, 3.0, 4, {0, 1}), primitive("P2", Mode::Additive, 0.5, 4, {0, 1, 2}),
                  primitive("P3", Mode::Additive, 0.1, 4, {0, 1, 3}), primitive("Cut", Mode::Subtractive, 1.0, 4, {2})};
  const Reduction r = reduce(p);
  EXPECT_EQ(r.primitive, (std::vector<int>{0, 1, 3}));
  const auto plans = find_plans(p, {1});
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(expression(p, plans[0]), "(P2 \u2212 Cut)");
  EXPECT_DOUBLE_EQ(plans[0].cost, enumerate_plans(p, 1).front().cost);
}

// Atoms 0 and 1 are in the same primitives, but only atom 1 is out of P2's reach once
// atom 2 is present: merged, the group is out of reach when either atom is.
TEST(SearchReductions, AtomsMergeIntoOneOnlyWithWhatBlocksEachOfThem) {
  PlanningProblem p;
  p.atoms = {{5, true, false}, {5, true, false}, {2, true, false}};
  p.primitives = {primitive("Base", Mode::Additive, 1.0, 3, {2}), primitive("P2", Mode::Additive, 0.5, 3, {0, 1}),
                  primitive("P3", Mode::Additive, 2.0, 3, {0, 1})};
  std::vector<AtomSet> reach(3, AtomSet{3});
  reach[1].set(2);
  p.primitives[1].blocked_by = std::make_shared<const AtomRelation>(std::move(reach));
  const Reduction r = reduce(p);
  EXPECT_EQ(r.problem.atoms.size(), 2u);
  for (SearchDirection direction : {SearchDirection::Forward, SearchDirection::Backward}) {
    SearchOptions options{3};
    options.direction = direction;
    const auto plans = find_plans(p, options);
    expect_same_plans(plans, enumerate_plans(p), 3, 0);
    ASSERT_FALSE(plans.empty());
    EXPECT_EQ(expression(p, plans[0]), "(P2 \u222A Base)");  // P2 only before Base
  }
}

// Backwards, a suffix may be extended past the point where a plan would already have
// reached the goal, or by an action that changes nothing once the rest is known: neither
// is a plan, and both directions list the same plans as the enumerator.
TEST(SearchReductions, APlanEndsWhereItFirstReachesTheGoalAndEveryStepChangesSomething) {
  PlanningProblem p;
  p.atoms = {{10, true, false}, {3, false, false}};
  p.primitives = {primitive("A", Mode::Additive, 1.0, 2, {0}), primitive("B", Mode::Additive, 0.1, 2, {0, 1}),
                  primitive("C", Mode::Subtractive, 0.1, 2, {1})};
  const auto oracle = enumerate_plans(p);
  for (SearchDirection direction : {SearchDirection::Forward, SearchDirection::Backward}) {
    SearchOptions options{10};
    options.direction = direction;
    expect_same_plans(find_plans(p, options), oracle, 10, 0);
  }
}

}  // namespace
}  // namespace hybridctl::planner
