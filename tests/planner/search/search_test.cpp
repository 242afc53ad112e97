// Plan search: the paper's worked example, A* against the exhaustive oracle on random
// instances, and every plan checked on the voxels it claims to make.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

#include "planner/search/bound.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

// A primitive of a hand-made problem; what the planner learns or derives is left empty.
PrimitiveSpec spec(std::string name, Mode mode, bool raw_stock, double cost_per_mm3, AtomSet atoms, std::string tool,
                   std::string setup) {
  PrimitiveSpec s;
  s.name = std::move(name);
  s.mode = mode;
  s.raw_stock = raw_stock;
  s.cost_per_mm3 = cost_per_mm3;
  s.atoms = std::move(atoms);
  s.tool = std::move(tool);
  s.setup = std::move(setup);
  return s;
}

using geometry::Box3;
using geometry::make_box;
using testing::make_problem;
using testing::random_instance;
using testing::VoxelPrimitive;
using testing::VoxelProblem;

const Lattice kUnit{1.0, {0, 0, 0}};

Solid rect(double x0, double y0, double x1, double y1) { return make_box(kUnit, {{x0, y0, 0}, {x1, y1, 1}}); }

// The four rectangles of the paper's Fig. 9: P2 and P4 disjoint, 11 of the 16
// canonical intersections non-empty (A_0011, A_0101, A_0111, A_1101, A_1111 empty).
VoxelProblem paper_example(bool p1_is_raw_stock) {
  std::vector<VoxelPrimitive> prims = {
      {"P1", Mode::Additive, p1_is_raw_stock, 1.0, rect(0, 0, 10, 6)},
      {"P2", Mode::Additive, false, 1.0, rect(7, 2, 14, 8)},
      {"P3", Mode::Subtractive, false, 1.0, rect(4, 4, 12, 10)},
      {"P4", Mode::Subtractive, false, 1.0, rect(2, -2, 6, 5)},
  };
  const IndexBox domain{{-1, -3, 0}, {15, 11, 1}};
  // Target A_0100 U A_1000 U A_1100: (P1 U P2) minus P3 and P4.
  const Solid design = subtract(subtract(unite(prims[0].region, prims[1].region), prims[2].region), prims[3].region);
  return make_problem(std::move(prims), design, domain);
}

std::set<std::string> expressions(const VoxelProblem& vp, const std::vector<Plan>& plans) {
  std::set<std::string> out;
  for (const Plan& p : plans) out.insert(expression(vp.problem, p));
  return out;
}

// The raw stock is clamped in the setup of the action after it, with that action's
// instrument loaded: no change is due there, even into a setup the part is re-clamped for
// by hand, while the same change between two actions costs the tool, the setup (a
// refixture) and the mode.
TEST(FixedCost, TheStepAfterARawStockCostsNoChange) {
  PlanningProblem p;
  p.fixed = {5.0, 3.0, 7.0, 13.0};
  AtomSet none(1);
  p.primitives = {spec("stock", Mode::Additive, true, 0.0, none, "", "top"),
                  spec("deposit", Mode::Additive, false, 1.0, none, "ded", "top"),
                  spec("mill", Mode::Subtractive, false, 1.0, none, "T1", "bottom")};
  p.primitives[2].refixture = true;
  EXPECT_EQ(fixed_cost(p, 0, 2), 0.0);
  EXPECT_EQ(fixed_cost(p, -1, 2), 0.0);
  EXPECT_EQ(fixed_cost(p, 1, 2), 5.0 + 13.0 + 7.0);
}

TEST(PaperExample, HasElevenNonEmptyAtoms) {
  const VoxelProblem vp = paper_example(false);
  EXPECT_EQ(vp.atoms.atom_count(), 11);
  std::set<std::string> codes;
  for (int a = 0; a < vp.atoms.atom_count(); ++a) codes.insert(vp.atoms.code(a).bits(4));
  for (const char* empty : {"0011", "0101", "0111", "1101", "1111"}) EXPECT_EQ(codes.count(empty), 0u) << empty;
}

TEST(PaperExample, FindsE1E2TheirP1P2SwapsAndE3ButNeverE4) {
  const VoxelProblem vp = paper_example(false);
  const auto plans = find_plans(vp.problem, {5});
  ASSERT_EQ(plans.size(), 5u);
  const std::set<std::string> expected = {
      "(((P1 \u222A P2) \u2212 P3) \u2212 P4)",  // E1
      "(((P1 \u222A P2) \u2212 P4) \u2212 P3)",  // E2
      "(((P2 \u222A P1) \u2212 P3) \u2212 P4)",
      "(((P2 \u222A P1) \u2212 P4) \u2212 P3)",
      "(((P1 \u2212 P4) \u222A P2) \u2212 P3)",  // E3
  };
  EXPECT_EQ(expressions(vp, plans), expected);
  // E4 = (((P1 - P4) - P3) U P2) leaves P2's part inside P3: not the design.
  Plan e4;
  e4.steps = {{0, 0, 0}, {3, 0, 0}, {2, 0, 0}, {1, 0, 0}};
  EXPECT_FALSE(testing::evaluate(vp, e4) == vp.design);
  for (const Plan& p : plans) EXPECT_EQ(testing::evaluate(vp, p), vp.design) << expression(vp.problem, p);
  // Costs are ordered and order matters: E1 and E2 remove different volumes.
  for (std::size_t i = 1; i < plans.size(); ++i) EXPECT_LE(plans[i - 1].cost, plans[i].cost);
}

TEST(PaperExample, PlansTheAcceptHookTurnsDownAreSkippedAndTheNextCheapestTakeTheirPlace) {
  const VoxelProblem vp = paper_example(false);
  const auto all = find_plans(vp.problem, {6});
  ASSERT_EQ(all.size(), enumerate_plans(vp.problem).size());  // the five there are
  // Turn down every plan whose first step is P1: the search must go on past them and
  // return the cheapest plans that do not start with P1, in cost order.
  SearchOptions options{3};
  std::vector<std::string> offered;
  options.accept = [&](const Plan& p) {
    offered.push_back(expression(vp.problem, p));
    return p.steps.front().primitive != 0;
  };
  SearchStats stats;
  const auto kept = find_plans(vp.problem, options, &stats);
  std::vector<Plan> expected;
  for (const Plan& p : enumerate_plans(vp.problem))
    if (p.steps.front().primitive != 0 && expected.size() < 3) expected.push_back(p);
  ASSERT_EQ(kept.size(), expected.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_NE(kept[i].steps.front().primitive, 0);
    EXPECT_NEAR(kept[i].cost, expected[i].cost, 1e-12);
  }
  EXPECT_EQ(stats.rejected, std::int64_t(offered.size() - kept.size()));
  EXPECT_GT(stats.rejected, 0);
}

TEST(PaperExample, TheSearchStopsAfterMaxRejectedPlansTurnedDown) {
  const VoxelProblem vp = paper_example(false);
  SearchOptions options{5};
  options.accept = [](const Plan&) { return false; };
  options.max_rejected = 4;
  SearchStats stats;
  EXPECT_TRUE(find_plans(vp.problem, options, &stats).empty());
  EXPECT_EQ(stats.rejected, 4);
  EXPECT_TRUE(stats.limit_reached);
}

// Plans known to fail (they begin as a rejected one did, up to where it failed) are passed
// over without being offered and without counting against max_rejected: with a limit of
// one rejection, the search still gets past every plan starting with P1, and returns the
// two that start with P2.
TEST(PaperExample, PlansKnownToFailArePassedOverWithoutBeingOfferedOrCounted) {
  const VoxelProblem vp = paper_example(false);
  SearchOptions options{3};
  std::vector<std::string> offered;
  options.accept = [&](const Plan& p) {
    offered.push_back(expression(vp.problem, p));
    return true;
  };
  options.known_to_fail = [](const Plan& p) { return p.steps.front().primitive == 0; };
  options.max_rejected = 1;
  SearchStats stats;
  const auto kept = find_plans(vp.problem, options, &stats);
  ASSERT_EQ(kept.size(), 2u);
  for (const Plan& p : kept) EXPECT_NE(p.steps.front().primitive, 0) << expression(vp.problem, p);
  for (const std::string& e : offered) EXPECT_EQ(e.find("((P1 "), std::string::npos) << e;
  EXPECT_EQ(stats.rejected, 0);
  EXPECT_GT(stats.known_to_fail, 0);
  EXPECT_FALSE(stats.limit_reached);
}

TEST(PaperExample, WithP1AsRawStockOnlyPlansStartingFromItRemain) {
  const VoxelProblem vp = paper_example(true);
  const auto plans = find_plans(vp.problem, {5});
  const std::set<std::string> expected = {
      "(((P1 \u222A P2) \u2212 P3) \u2212 P4)",
      "(((P1 \u222A P2) \u2212 P4) \u2212 P3)",
      "(((P1 \u2212 P4) \u222A P2) \u2212 P3)",
  };
  EXPECT_EQ(expressions(vp, plans), expected);
}

TEST(Search, BothDirectionsFindTheSameOptimaAsTheExhaustiveEnumerator) {
  std::mt19937 rng(2018);
  int solvable = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 6;  // 2..7 primitives
    VoxelProblem vp = random_instance(rng, n);
    vp.problem.fixed = {trial % 3 == 0 ? 5.0 : 0.0, 0, trial % 4 == 0 ? 7.0 : 0.0};
    for (auto& p : vp.problem.primitives) p.tool = "T" + std::to_string(rng() % 2);
    const auto oracle = enumerate_plans(vp.problem);
    for (SearchDirection direction : {SearchDirection::Forward, SearchDirection::Backward}) {
      SearchOptions options{5};
      options.direction = direction;
      const auto found = find_plans(vp.problem, options);
      ASSERT_EQ(found.size(), std::min<std::size_t>(5, oracle.size())) << "trial " << trial;
      for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_NEAR(found[i].cost, oracle[i].cost, 1e-9 * std::max(1.0, oracle[i].cost)) << "trial " << trial << " plan " << i;
        EXPECT_TRUE(is_goal(vp.problem, found[i].final_state));
        // What the atoms promise is what the voxels give.
        EXPECT_EQ(testing::evaluate(vp, found[i]), testing::atoms_union(vp, found[i].final_state)) << "trial " << trial;
      }
      std::set<std::vector<int>> distinct;
      for (const Plan& p : found) {
        std::vector<int> seq;
        for (const PlanStep& s : p.steps) seq.push_back(s.primitive);
        distinct.insert(seq);
      }
      EXPECT_EQ(distinct.size(), found.size());
    }
    solvable += !oracle.empty();
  }
  EXPECT_GT(solvable, 150);  // the generator really makes solvable instances
}

TEST(Search, PlansObeyC1ToC4) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const VoxelProblem vp = random_instance(rng, 5);
    for (const Plan& plan : enumerate_plans(vp.problem)) {
      ASSERT_FALSE(plan.steps.empty());
      EXPECT_EQ(vp.problem.primitives[std::size_t(plan.steps[0].primitive)].mode, Mode::Additive);  // C3
      std::set<int> used;
      for (std::size_t s = 0; s < plan.steps.size(); ++s) {
        const int i = plan.steps[s].primitive;
        if (s > 0) {
          EXPECT_FALSE(vp.problem.primitives[std::size_t(i)].raw_stock);  // C4
        }
        EXPECT_TRUE(used.insert(i).second);  // each primitive once by default
        EXPECT_GT(plan.steps[s].volume, 0);  // no action that changes nothing
      }
    }
  }
}

TEST(Search, ReuseUpToKTimesAgreesWithTheOracleToo) {
  std::mt19937 rng(99);
  int reused = 0;
  for (int trial = 0; trial < 60; ++trial) {
    VoxelProblem vp = random_instance(rng, 2 + trial % 3);
    vp.problem.max_uses = 2;
    const auto oracle = enumerate_plans(vp.problem);
    const auto found = find_plans(vp.problem, {5});
    ASSERT_EQ(found.size(), std::min<std::size_t>(5, oracle.size())) << "trial " << trial;
    for (std::size_t i = 0; i < found.size(); ++i) {
      EXPECT_NEAR(found[i].cost, oracle[i].cost, 1e-9 * std::max(1.0, oracle[i].cost)) << "trial " << trial;
      EXPECT_EQ(testing::evaluate(vp, found[i]), testing::atoms_union(vp, found[i].final_state));
    }
    for (const Plan& p : oracle) {
      std::multiset<int> uses;
      for (const PlanStep& s : p.steps) uses.insert(s.primitive);
      for (int i : uses) EXPECT_LE(uses.count(i), 2u);
      for (int i : uses) reused += uses.count(i) == 2;
    }
  }
  EXPECT_GT(reused, 0);  // reuse really occurs in these plans
}

// Whether a plan keeps the cheapest order of each block (consecutive actions with the
// same mode, tool and setup): raw stock first, then by cost per mm^3, then by index.
bool in_block_order(const PlanningProblem& p, const Plan& plan) {
  for (std::size_t s = 1; s < plan.steps.size(); ++s) {
    const int i = plan.steps[s - 1].primitive, j = plan.steps[s].primitive;
    const PrimitiveSpec& a = p.primitives[std::size_t(i)];
    const PrimitiveSpec& b = p.primitives[std::size_t(j)];
    if (a.mode != b.mode || a.tool != b.tool || a.setup != b.setup) continue;
    if (std::make_tuple(!a.raw_stock, a.cost_per_mm3, i) > std::make_tuple(!b.raw_stock, b.cost_per_mm3, j)) return false;
  }
  return true;
}

TEST(Search, OneOrderPerBlockFindsTheOptimumAndTheCheapestPlansInBlockOrder) {
  std::mt19937 rng(2026);
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 7;  // 2..8 primitives
    VoxelProblem vp = random_instance(rng, n);
    vp.problem.fixed = {trial % 3 == 0 ? 5.0 : 0.0, trial % 5 == 0 ? 3.0 : 0.0, trial % 4 == 0 ? 7.0 : 0.0,
                        trial % 6 == 0 ? 11.0 : 0.0};
    for (auto& p : vp.problem.primitives) {
      p.tool = "T" + std::to_string(rng() % 2);
      p.setup = rng() % 3 == 0 ? "side" : "top";
      p.refixture = trial % 2 == 0 && p.setup == "side";  // the part re-clamped by hand for it
    }
    const auto oracle = enumerate_plans(vp.problem);
    std::vector<Plan> ordered;
    for (const Plan& p : oracle)
      if (in_block_order(vp.problem, p)) ordered.push_back(p);
    SearchOptions options{5};
    options.block_orders = BlockOrders::Cheapest;
    options.direction = trial / 2 % 2 ? SearchDirection::Forward : SearchDirection::Backward;
    SearchStats stats;
    const auto found = find_plans(vp.problem, options, &stats);
    ASSERT_EQ(found.size(), std::min<std::size_t>(5, ordered.size())) << "trial " << trial;
    if (!oracle.empty()) {
      // Keeping one order per block loses no optimum.
      ASSERT_FALSE(found.empty());
      EXPECT_NEAR(found.front().cost, oracle.front().cost, 1e-9 * std::max(1.0, oracle.front().cost)) << "trial " << trial;
      EXPECT_NEAR(stats.lower_bound, oracle.front().cost, 1e-9 * std::max(1.0, oracle.front().cost));
      ++compared;
    }
    for (std::size_t i = 0; i < found.size(); ++i) {
      EXPECT_TRUE(in_block_order(vp.problem, found[i]));
      EXPECT_TRUE(found[i].exact);
      EXPECT_NEAR(found[i].cost, ordered[i].cost, 1e-9 * std::max(1.0, ordered[i].cost)) << "trial " << trial;
      EXPECT_EQ(testing::evaluate(vp, found[i]), testing::atoms_union(vp, found[i].final_state)) << "trial " << trial;
    }
  }
  EXPECT_GT(compared, 150);
}

// Two removals with one tool: the cheaper must go first, since the atoms both hold are
// paid at the rate of whichever comes first. One order per block keeps that one.
// What a plan does step by step: each step's tool, setup and mode and the atoms it changes.
std::vector<std::string> effect(const PlanningProblem& p, const Plan& plan) {
  std::vector<std::string> out;
  AtomSet state(int(p.atoms.size()));
  for (const PlanStep& step : plan.steps) {
    const PrimitiveSpec& prim = p.primitives[std::size_t(step.primitive)];
    std::string e = prim.tool + "|" + prim.setup + "|" + (prim.mode == Mode::Additive ? "+" : "-");
    for (int a = 0; a < int(p.atoms.size()); ++a) {
      const bool changes = prim.atoms.test(a) && (prim.mode == Mode::Additive) != state.test(a);
      if (changes) e += " " + std::to_string(a);
      if (prim.atoms.test(a)) state.set(a, prim.mode == Mode::Additive);
    }
    out.push_back(e);
  }
  return out;
}

TEST(Search, PlansThatDoTheSameStepByStepAreOnePlanTheCheapestKept) {
  std::mt19937 rng(16);
  int merged = 0;
  for (int trial = 0; trial < 200; ++trial) {
    VoxelProblem vp = random_instance(rng, 2 + trial % 3);
    // A band of each primitive, as planner/primitives/bands.hpp makes them: its upper half, with its
    // tool and cost.
    std::vector<VoxelPrimitive> prims = vp.primitives;
    std::vector<std::size_t> parent;
    for (std::size_t i = 0; i < vp.primitives.size(); ++i) parent.push_back(i);
    for (std::size_t i = 0; i < vp.primitives.size(); ++i) {
      const VoxelPrimitive& p = vp.primitives[i];
      if (p.raw) continue;
      const IndexBox b = p.region.bounding_box();
      const IndexBox upper{{b.lo.x, b.lo.y, (b.lo.z + b.hi.z) / 2}, b.hi};
      prims.push_back({p.name + "b", p.mode, false, p.cost, intersect(p.region, Solid::filled(kUnit, upper))});
      parent.push_back(i);
    }
    vp = make_problem(std::move(prims), vp.design, vp.domain);
    for (std::size_t i = 0; i < vp.problem.primitives.size(); ++i)
      vp.problem.primitives[i].tool = "T" + std::to_string(parent[i] % 2);
    // The oracle: every plan, cheapest first, the first of each effect kept.
    std::vector<Plan> distinct;
    std::set<std::vector<std::string>> seen;
    for (const Plan& plan : enumerate_plans(vp.problem))
      if (seen.insert(effect(vp.problem, plan)).second) distinct.push_back(plan);
      else ++merged;
    SearchOptions options{5};
    options.distinct_effects = true;
    const auto found = find_plans(vp.problem, options);
    ASSERT_EQ(found.size(), std::min<std::size_t>(5, distinct.size())) << "trial " << trial;
    std::set<std::vector<std::string>> effects;
    for (std::size_t i = 0; i < found.size(); ++i) {
      EXPECT_NEAR(found[i].cost, distinct[i].cost, 1e-9 * std::max(1.0, distinct[i].cost)) << "trial " << trial;
      EXPECT_TRUE(effects.insert(effect(vp.problem, found[i])).second) << "trial " << trial;
    }
  }
  EXPECT_GT(merged, 20);  // the instances do hold plans that do the same thing
}

TEST(Search, ARemovalWhoseCostDependsOnTheOrderIsCostedInItsCheapestOrder) {
  // Atoms: 0 core (must-in), 1 in both removals, 2 only in the dear one, 3 only in the
  // cheap one (all must-out); the stock holds them all.
  PlanningProblem p;
  p.atoms = {{10, true, false}, {8, false, true}, {1, false, true}, {1, false, true}};
  auto prim = [&](std::string name, Mode mode, double cost, std::initializer_list<int> atoms, bool raw = false) {
    PrimitiveSpec s = spec(std::move(name), mode, raw, cost, AtomSet(4), "T1", "top");
    for (int a : atoms) s.atoms.set(a);
    if (raw) s.tool = "stock";
    return s;
  };
  p.primitives = {prim("Dear", Mode::Subtractive, 3.0, {1, 2}), prim("Cheap", Mode::Subtractive, 1.0, {1, 3}),
                  prim("Stock", Mode::Additive, 0.0, {0, 1, 2, 3}, true)};
  for (BlockOrders orders : {BlockOrders::Every, BlockOrders::Cheapest}) {
    SearchOptions options{1};
    options.block_orders = orders;
    const auto plans = find_plans(p, options);
    ASSERT_EQ(plans.size(), 1u);
    EXPECT_EQ(expression(p, plans[0]), "((Stock \u2212 Cheap) \u2212 Dear)");
    EXPECT_DOUBLE_EQ(plans[0].cost, 1.0 * 9 + 3.0 * 1 + 5.0 * 0);  // stock costs nothing
    EXPECT_DOUBLE_EQ(plans[0].cost, enumerate_plans(p, 1).front().cost);
  }
}

// A primitive that changes no must-in or must-out atom can still pay: a cheap roughing
// pass over atoms free either way leaves less to the dear tool that must follow.
TEST(Search, APrimitiveThatTouchesOnlyFreeAtomsIsKeptWhenItLowersTheCost) {
  PlanningProblem p;
  p.atoms = {{10, true, false}, {20, false, false}, {2, false, true}};  // core, free band, must-out
  PrimitiveSpec stock = spec("Stock", Mode::Additive, true, 0.0, AtomSet(3), "stock", "");
  PrimitiveSpec rough = spec("Rough", Mode::Subtractive, false, 0.1, AtomSet(3), "T1", "top");
  PrimitiveSpec finish = spec("Finish", Mode::Subtractive, false, 2.0, AtomSet(3), "T2", "top");
  for (int a : {0, 1, 2}) stock.atoms.set(a);
  rough.atoms.set(1);
  finish.atoms.set(1);
  finish.atoms.set(2);
  p.primitives = {stock, rough, finish};
  p.fixed = {1.0, 20.0, 40.0};
  const auto plans = find_plans(p, {1});
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(expression(p, plans[0]), "((Stock \u2212 Rough) \u2212 Finish)");
  EXPECT_DOUBLE_EQ(plans[0].cost, enumerate_plans(p, 1).front().cost);
}

// A fixed cost that changes the best order: three removals, two with tool T1. By rate
// alone the order is A (T1), B (T2), C (T1), with two tool changes; keeping T1's actions
// together saves one change and costs more in volume only when the change is cheap.
TEST(Search, AToolChangeCostThatChangesTheBestOrderIsHonoured) {
  for (double tool_change : {0.0, 50.0}) {
    PlanningProblem p;
    p.atoms = {{10, true, false}, {4, false, true}, {4, false, true}, {4, false, true}, {1, false, true}};
    PrimitiveSpec stock = spec("Stock", Mode::Additive, true, 0.0, AtomSet(5), "stock", "");
    for (int a = 0; a < 5; ++a) stock.atoms.set(a);
    PrimitiveSpec a = spec("A", Mode::Subtractive, false, 1.0, AtomSet(5), "T1", "top");
    PrimitiveSpec b = spec("B", Mode::Subtractive, false, 2.0, AtomSet(5), "T2", "top");
    PrimitiveSpec c = spec("C", Mode::Subtractive, false, 3.0, AtomSet(5), "T1", "top");
    a.atoms.set(1);
    b.atoms.set(2), b.atoms.set(4);
    c.atoms.set(3), c.atoms.set(4);
    p.primitives = {stock, a, b, c};
    p.fixed = {tool_change, 0, 0};
    for (BlockOrders orders : {BlockOrders::Every, BlockOrders::Cheapest}) {
      SearchOptions options{1};
      options.block_orders = orders;
      const auto plans = find_plans(p, options);
      ASSERT_EQ(plans.size(), 1u);
      EXPECT_DOUBLE_EQ(plans[0].cost, enumerate_plans(p, 1).front().cost) << tool_change;
      // With a dear tool change T1's two removals are neighbours.
      const std::string e = expression(p, plans[0]);
      if (tool_change > 0) {
        EXPECT_TRUE(e.find("A) \u2212 C)") != std::string::npos || e.find("C) \u2212 A)") != std::string::npos) << e;
      }
    }
  }
}

// The lower bound is admissible and consistent: along every plan the enumerator finds,
// it never exceeds what the rest of the plan costs, nor falls by more than a step costs
// (but for a step that lays a must-in atom it cannot lay last, which is not consistent).
TEST(Search, TheLowerBoundNeverOverestimatesAndFallsByAtMostAStepsCost) {
  std::mt19937 rng(16);
  int checked = 0;
  for (int trial = 0; trial < 80; ++trial) {
    VoxelProblem vp = random_instance(rng, 2 + trial % 5);
    // With a tolerance band there are free atoms, whose side effects the bound counts.
    vp = make_problem(vp.primitives, vp.design, vp.domain, trial % 2 ? 1.0 : 0.0);
    vp.problem.fixed = {trial % 3 ? 5.0 : 0.0, trial % 4 ? 3.0 : 0.0, trial % 5 ? 7.0 : 0.0, trial % 6 ? 13.0 : 1.0};
    for (auto& p : vp.problem.primitives) {
      p.tool = "T" + std::to_string(rng() % 3);
      p.setup = rng() % 3 == 0 ? "bottom" : rng() % 2 ? "side" : "top";
      p.refixture = trial % 2 == 0 && p.setup == "bottom";  // the part turned over by hand
    }
    const LowerBound bound(vp.problem);
    for (const Plan& plan : enumerate_plans(vp.problem, 200)) {
      AtomSet state(int(vp.problem.atoms.size()));
      std::vector<std::uint8_t> uses(vp.problem.primitives.size(), 0);
      double rest = plan.cost, h = bound(state, uses, -1);
      for (const PlanStep& step : plan.steps) {
        EXPECT_LE(h, rest + 1e-9) << "trial " << trial;
        const PrimitiveSpec& prim = vp.problem.primitives[std::size_t(step.primitive)];
        for (std::size_t w = 0; w < state.words().size(); ++w)
          state.words()[w] = prim.mode == Mode::Additive ? state.words()[w] | prim.atoms.words()[w]
                                                         : state.words()[w] & ~prim.atoms.words()[w];
        ++uses[std::size_t(step.primitive)];
        const double next = bound(state, uses, step.primitive);
        bool lays_early = false;  // a must-in atom laid that a later action must cut and lay again
        for (int a = 0; a < int(vp.problem.atoms.size()); ++a)
          lays_early = lays_early || (prim.mode == Mode::Additive && prim.atoms.test(a) &&
                                      vp.problem.atoms[std::size_t(a)].must_in && !bound.lays_last(step.primitive, a));
        if (!lays_early) {
          EXPECT_LE(h, step.cost + next + 1e-9) << "trial " << trial << ": the bound fell by more than a step";
        }
        EXPECT_LE(bound.quick(state, uses, step.primitive), next + 1e-12);
        h = next;
        rest -= step.cost;
        ++checked;
      }
      EXPECT_NEAR(h, 0, 1e-12);  // nothing is owed at the goal
    }
  }
  EXPECT_GT(checked, 1000);
}

// A block's design that the only removal of its waste cuts is laid again after that
// removal: the atom part charges it at the rate of the head that lays it without waste,
// not at the cheap overfilling one's. On a strip: the design [0, 4) (C lays it with the
// waste [4, 6) at rate 1, D exactly at rate 5); R, the only removal of the waste, also
// cuts [2, 4). C may lay [0, 2) last, never [2, 4): whichever plan, [2, 4) is laid by D.
TEST(Search, TheBoundChargesDesignAtTheRateOfWhatMayLayItLast) {
  std::vector<VoxelPrimitive> prims = {
      {"C", Mode::Additive, false, 1.0, rect(0, 0, 6, 1)},
      {"D", Mode::Additive, false, 5.0, rect(0, 0, 4, 1)},
      {"R", Mode::Subtractive, false, 1.0, rect(2, 0, 6, 1)},
  };
  const VoxelProblem vp = make_problem(std::move(prims), rect(0, 0, 4, 1), {{0, 0, 0}, {6, 1, 1}});
  const LowerBound bound(vp.problem);
  int kept = -1, cut = -1;  // the atoms [0, 2) and [2, 4)
  for (int a = 0; a < int(vp.problem.atoms.size()); ++a)
    if (vp.problem.atoms[std::size_t(a)].must_in) (vp.problem.primitives[2].atoms.test(a) ? cut : kept) = a;
  ASSERT_GE(kept, 0);
  ASSERT_GE(cut, 0);
  EXPECT_TRUE(bound.lays_last(0, kept));
  EXPECT_FALSE(bound.lays_last(0, cut));
  EXPECT_TRUE(bound.lays_last(1, cut));
  const double optimum = enumerate_plans(vp.problem, 1).front().cost;
  const double h = bound(AtomSet(int(vp.problem.atoms.size())), std::vector<std::uint8_t>(3, 0), -1);
  EXPECT_GE(h * vp.problem.normaliser, 2 * 1.0 + 2 * 5.0);  // [0, 2) by C, [2, 4) by D at least
  EXPECT_LE(h, optimum + 1e-12);
  EXPECT_DOUBLE_EQ(find_plans(vp.problem, {1}).front().cost, optimum);
}

// A block whose waste each removal clears only by cutting part of the design (the bushing's
// bore): that part is laid again, by the overfilling head C only if its waste, absent now,
// is laid and cut too, or else by the exact head D. Per atom, some removal spares each
// design atom, so C may lay any of it last; the bound charges the cheaper of C's side
// effects and D's rate beyond C's on the design a removal cuts. On a 4 x 3 grid: design
// row y = 0, stock S rows 0-1 (waste row 1), C rows 0-2 (waste rows 1-2), R1 and R2 clear
// rows 1-2 and the design's left or right half.
TEST(Search, TheBoundChargesDesignCutAndLaidAgainAtTheDearerHeadOrTheCheapOnesWaste) {
  std::vector<VoxelPrimitive> prims = {
      {"S", Mode::Additive, true, 0.0, rect(0, 0, 4, 2)},
      {"C", Mode::Additive, false, 1.0, rect(0, 0, 4, 3)},
      {"D", Mode::Additive, false, 5.0, rect(0, 0, 4, 1)},
      {"R1", Mode::Subtractive, false, 1.0, unite(rect(0, 1, 4, 3), rect(0, 0, 2, 1))},
      {"R2", Mode::Subtractive, false, 1.0, unite(rect(0, 1, 4, 3), rect(2, 0, 4, 1))},
  };
  const VoxelProblem vp = make_problem(std::move(prims), rect(0, 0, 4, 1), {{0, 0, 0}, {4, 3, 1}});
  const LowerBound bound(vp.problem);
  for (int a = 0; a < int(vp.problem.atoms.size()); ++a)
    if (vp.problem.atoms[std::size_t(a)].must_in) {
      EXPECT_TRUE(bound.lays_last(1, a));
    }
  // After S: its waste row costs 4 to remove, the removal cuts 2 cells of design, laid
  // again at C's rate 1 at least; and then either C's absent row of waste is laid and
  // removed (4 x (1 + 1)) or the 2 cells cost D's 5, 4 more each: 2 + 4 + 8. The best
  // completion: R1 (6), D (2 x 5).
  const AtomSet after_stock = vp.problem.primitives[0].atoms;
  std::vector<std::uint8_t> uses(5, 0);
  uses[0] = 1;
  const double h = bound(after_stock, uses, 0);
  EXPECT_GE(h * vp.problem.normaliser, 14 - 1e-9);
  EXPECT_LE(h * vp.problem.normaliser, 16 + 1e-9);
  const double optimum = enumerate_plans(vp.problem, 1).front().cost;
  EXPECT_NEAR(optimum * vp.problem.normaliser, 16, 1e-9);
  EXPECT_DOUBLE_EQ(find_plans(vp.problem, {1}).front().cost, optimum);
}

// Stopped early, the search still answers: plans from weighted A*, each with a gap that
// holds against the true optimum, and a lower bound that does not exceed it.
TEST(Search, StoppedEarlyItReturnsPlansWithAProvenGap) {
  std::mt19937 rng(404);
  int inexact = 0;
  for (int trial = 0; trial < 120; ++trial) {
    VoxelProblem vp = random_instance(rng, 5 + trial % 4);
    vp.problem.fixed = {2.0, 0, 4.0};
    const auto oracle = enumerate_plans(vp.problem, 1);
    if (oracle.empty()) continue;
    const double optimum = oracle.front().cost;
    // Expansions: rarely enough to prove anything, in either direction.
    for (const auto& [direction, limit] : {std::pair{SearchDirection::Forward, 3}, {SearchDirection::Forward, 5},
                                           {SearchDirection::Forward, 8}, {SearchDirection::Backward, 1},
                                           {SearchDirection::Backward, 2}, {SearchDirection::Backward, 3}}) {
      SearchOptions options{3, limit};
      options.direction = direction;
      SearchStats stats;
      const auto found = find_plans(vp.problem, options, &stats);
      if (found.empty()) {
        EXPECT_TRUE(stats.limit_reached) << "trial " << trial;
        continue;
      }
      EXPECT_LE(stats.lower_bound, optimum + 1e-9) << "trial " << trial;
      for (std::size_t i = 0; i < found.size(); ++i) {
        EXPECT_TRUE(is_goal(vp.problem, found[i].final_state));
        EXPECT_LE(found[i].cost, (1 + found[i].gap) * optimum + 1e-9) << "trial " << trial;
        EXPECT_GE(found[i].cost, optimum - 1e-9);
        if (i > 0) {
          EXPECT_LE(found[i - 1].cost, found[i].cost);
        }
        if (i == 0 && found[i].exact) {
          EXPECT_NEAR(found[i].cost, optimum, 1e-9 * std::max(1.0, optimum));
        }
        inexact += !found[i].exact;
      }
    }
  }
  EXPECT_GT(inexact, 20);  // the limit really cut the exact search short
}

// With a plan in hand (here a seed, the optimum itself), each weighted pass after the
// exact search gets a quarter of the expansion limit: the passes hunt for more plans, and
// one weight finds them in a few expansions where another finds none in the whole limit.
TEST(Search, WithAPlanInHandEachWeightedPassGetsAQuarterOfTheLimit) {
  std::mt19937 rng(77);
  int cut_short = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const VoxelProblem vp = random_instance(rng, 8);
    const auto oracle = enumerate_plans(vp.problem, 1);
    if (oracle.empty()) continue;
    SearchOptions options{50, 40};  // more plans than the passes find: each runs to its limit
    options.direction = SearchDirection::Forward;
    std::vector<int> best;
    for (const PlanStep& step : oracle.front().steps) best.push_back(step.primitive);
    options.seeds = {best};
    SearchStats stats;
    const auto found = find_plans(vp.problem, options, &stats);
    if (!stats.limit_reached) continue;  // the exact search found every plan
    ++cut_short;
    ASSERT_FALSE(found.empty());
    EXPECT_NEAR(found.front().cost, oracle.front().cost, 1e-9);
    EXPECT_LE(stats.expanded, 40 + 3 * 10) << "trial " << trial;
  }
  EXPECT_GT(cut_short, 5);
}

TEST(Search, AnUnreachableDesignYieldsNoPlan) {
  std::vector<VoxelPrimitive> prims = {{"A", Mode::Additive, false, 1.0, rect(0, 0, 4, 4)}};
  const Solid design = rect(0, 0, 2, 2);  // a quarter of A: no primitive removes the rest
  const VoxelProblem vp = make_problem(prims, design, {{0, 0, 0}, {4, 4, 1}});
  SearchStats stats;
  EXPECT_TRUE(find_plans(vp.problem, {5}, &stats).empty());
  EXPECT_TRUE(stats.exhausted);
  EXPECT_TRUE(enumerate_plans(vp.problem).empty());
}

}  // namespace
}  // namespace hybridctl::planner
