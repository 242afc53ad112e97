// Plans built step by step: what greedy_sequences builds (plans that reach the goal, in cost
// order, never a removal through the design present), and that find_plans offers them with
// their proven gap when the exact search stops at its limit.

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "planner/search/greedy.hpp"
#include "planner/search/steps.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

using geometry::make_box;
using testing::make_problem;
using testing::VoxelPrimitive;
using testing::VoxelProblem;

const Lattice kUnit{1.0, {0, 0, 0}};

Solid box(double x0, double y0, double x1, double y1) { return make_box(kUnit, {{x0, y0, 0}, {x1, y1, 1}}); }

// A block to mill a step into, with many removals: two cheap roughers that each clear one
// half of the waste, dearer finishers that clear it all, and a cutter through the design.
// A deposit of the part itself is dearer than milling it from the block, and its first
// actions look cheaper to the bound than the block's.
VoxelProblem block_and_cutters() {
  const Solid design = box(0, 0, 10, 4);
  std::vector<VoxelPrimitive> prims = {
      {"block", Mode::Additive, true, 0.0, box(0, 0, 10, 8)},
      {"deposit", Mode::Additive, false, 3.0, box(0, 0, 10, 5)},
      {"rougher left", Mode::Subtractive, false, 0.1, box(0, 4, 5, 9)},
      {"rougher right", Mode::Subtractive, false, 0.1, box(5, 4, 10, 9)},
      {"finisher", Mode::Subtractive, false, 1.0, box(0, 4, 10, 9)},
      {"through the design", Mode::Subtractive, false, 0.01, box(0, 2, 10, 9)},
  };
  return make_problem(std::move(prims), design, {{-1, -1, 0}, {11, 10, 1}});
}

TEST(GreedySequences, MillTheBlockWithTheCheapestCuttersThatSpareTheDesign) {
  const VoxelProblem vp = block_and_cutters();
  const auto sequences = greedy_sequences(vp.problem, 10);
  ASSERT_FALSE(sequences.empty());
  Plan best;
  ASSERT_TRUE(simulate(vp.problem, sequences.front(), best));
  EXPECT_EQ(expression(vp.problem, best), "((block \u2212 rougher left) \u2212 rougher right)");
  EXPECT_EQ(testing::evaluate(vp, best), vp.design);
}

TEST(GreedySequences, EveryPlanReachesTheGoalOnceAndTheyComeCheapestFirst) {
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> at(0, 10), size(2, 8), cost(0.2, 3.0);
  int built = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 3 + trial % 6;
    std::vector<VoxelPrimitive> prims;
    for (int i = 0; i < n; ++i) {
      const Mode mode = i == 0 || rng() % 2 ? Mode::Additive : Mode::Subtractive;
      const double x = at(rng), y = at(rng);
      prims.push_back({"P" + std::to_string(i + 1), mode, i == 0, cost(rng), box(x, y, x + size(rng), y + size(rng))});
    }
    // The design: the first box less what two removals take, so that some plan exists.
    Solid design = prims[0].region;
    for (int i = 1, taken = 0; i < n && taken < 2; ++i)
      if (prims[std::size_t(i)].mode == Mode::Subtractive) design = subtract(design, prims[std::size_t(i)].region), ++taken;
    const VoxelProblem vp = make_problem(std::move(prims), design, {{-1, -1, 0}, {19, 19, 1}});
    const auto sequences = greedy_sequences(vp.problem, 5);
    const auto oracle = enumerate_plans(vp.problem, 1);
    if (oracle.empty()) {
      EXPECT_TRUE(sequences.empty()) << "trial " << trial;
    }
    std::set<std::vector<int>> distinct(sequences.begin(), sequences.end());
    EXPECT_EQ(distinct.size(), sequences.size()) << "trial " << trial;
    double previous = 0;
    for (const auto& sequence : sequences) {
      Plan plan;
      ASSERT_TRUE(simulate(vp.problem, sequence, plan)) << "trial " << trial;
      EXPECT_TRUE(is_goal(vp.problem, plan.final_state)) << "trial " << trial;
      EXPECT_EQ(testing::evaluate(vp, plan), testing::atoms_union(vp, plan.final_state)) << "trial " << trial;
      ASSERT_FALSE(oracle.empty());
      EXPECT_GE(plan.cost, oracle.front().cost - 1e-12) << "trial " << trial;  // never cheaper than the optimum
      EXPECT_GE(plan.cost, previous) << "trial " << trial;
      previous = plan.cost;
      ++built;
    }
  }
  EXPECT_GT(built, 50);  // the generator gives plans to build, the test is not vacuous
}

TEST(GreedySequences, NoneWhenTheDesignCannotBeReachedWithoutCuttingIt) {
  // The only removal cuts into the design; a plan would have to deposit it again, which no
  // deposit here can do without the waste.
  const Solid design = box(0, 0, 10, 4);
  std::vector<VoxelPrimitive> prims = {
      {"block", Mode::Additive, true, 0.0, box(0, 0, 10, 8)},
      {"through the design", Mode::Subtractive, false, 0.1, box(0, 2, 10, 9)},
  };
  const VoxelProblem vp = make_problem(std::move(prims), design, {{-1, -1, 0}, {11, 10, 1}});
  EXPECT_TRUE(greedy_sequences(vp.problem, 5).empty());
}

TEST(Search, WhenTheExactSearchStopsAtItsLimitPlansBuiltStepByStepAreOfferedWithTheirGap) {
  const VoxelProblem vp = block_and_cutters();
  SearchOptions options{1};
  options.max_expansions = 1;  // the exact search proves nothing
  options.direction = SearchDirection::Forward;  // whose bound after one expansion is above 0
  SearchStats stats;
  const auto plans = find_plans(vp.problem, options, &stats);
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_TRUE(stats.limit_reached);
  EXPECT_FALSE(plans.front().exact);
  EXPECT_EQ(testing::evaluate(vp, plans.front()), vp.design);
  EXPECT_TRUE(std::isfinite(plans.front().gap));
  // The optimum, which the exhaustive enumerator knows, is the block milled by the roughers.
  const auto oracle = enumerate_plans(vp.problem, 1);
  ASSERT_FALSE(oracle.empty());
  EXPECT_NEAR(plans.front().cost, oracle.front().cost, 1e-12);
  EXPECT_TRUE(plans.front().built);
}

// Two plans wanted, the exact search (forwards) stopped at once, `seed` offered; every plan
// is accepted and its primitives recorded in order.
SearchOptions stopped_with_seed(std::vector<int> seed, std::vector<std::vector<int>>& offered) {
  SearchOptions options{2};
  options.max_expansions = 1;
  options.direction = SearchDirection::Forward;
  options.seeds = {std::move(seed)};
  options.accept = [&offered](const Plan& plan) {
    offered.push_back(detail::sequence_of(plan));
    return true;
  };
  return options;
}

// A sequence found elsewhere (the proof's replay, planner/search/core_proof.hpp) is judged with
// the plans built step by step, and comes first among them.
TEST(Search, WhenTheExactSearchStopsAtItsLimitASeedIsOfferedWithItsGap) {
  const VoxelProblem vp = block_and_cutters();
  std::vector<std::vector<int>> offered;
  const SearchOptions options = stopped_with_seed({0, 4}, offered);  // the block, milled by the finisher
  SearchStats stats;
  const auto plans = find_plans(vp.problem, options, &stats);
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_FALSE(offered.empty());
  EXPECT_EQ(offered.front(), (std::vector<int>{0, 4}));
  const auto seeded = std::find_if(plans.begin(), plans.end(), [](const Plan& p) { return p.replayed; });
  ASSERT_NE(seeded, plans.end());
  EXPECT_FALSE(seeded->exact);
  EXPECT_FALSE(seeded->built);
  EXPECT_EQ(expression(vp.problem, *seeded), "(block \u2212 finisher)");
  EXPECT_TRUE(std::isfinite(seeded->gap));
  EXPECT_EQ(testing::evaluate(vp, *seeded), vp.design);
}

// The search runs on the problem reduced to the primitives a plan can hold, numbered
// anew: a seed is given in the caller's numbering, and offered as the plan it names. Here
// the spill (waste no removal reaches) is left out, so the finisher is the fifth primitive
// of the reduced problem and the sixth of the caller's.
TEST(Search, ASeedIsTheCallersPlanWhenTheSearchLeavesPrimitivesOut) {
  VoxelProblem base = block_and_cutters();
  std::vector<VoxelPrimitive> prims = base.primitives;
  prims.insert(prims.begin() + 1, {"spill", Mode::Additive, false, 0.5, box(0, 0, 10, 10)});
  const VoxelProblem vp = make_problem(std::move(prims), base.design, base.domain);
  std::vector<std::vector<int>> offered;
  const SearchOptions options = stopped_with_seed({0, 5}, offered);  // the block, milled by the finisher
  const auto plans = find_plans(vp.problem, options);
  ASSERT_FALSE(offered.empty());
  EXPECT_EQ(offered.front(), (std::vector<int>{0, 5}));
  const auto seeded = std::find_if(plans.begin(), plans.end(), [](const Plan& p) { return p.replayed; });
  ASSERT_NE(seeded, plans.end());
  EXPECT_EQ(expression(vp.problem, *seeded), "(block \u2212 finisher)");
  EXPECT_EQ(testing::evaluate(vp, *seeded), vp.design);
}

}  // namespace
}  // namespace hybridctl::planner
