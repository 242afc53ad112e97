// Raw stocks proven on their own before the search (planner/search/start_proofs.hpp,
// docs/search.md): a stock no plan starts from is never a first action, one that starts a
// plan gives that plan, and the optimum is the same either way.

#include <gtest/gtest.h>

#include <random>

#include "planner/search/steps.hpp"
#include "planner/search/start_proofs.hpp"
#include "../planner_fixtures.hpp"

namespace hybridctl::planner {
namespace {

PrimitiveSpec primitive(std::string name, Mode mode, int atoms, std::initializer_list<int> held, bool raw_stock = false) {
  PrimitiveSpec s;
  s.name = std::move(name);
  s.mode = mode;
  s.raw_stock = raw_stock;
  s.cost_per_mm3 = raw_stock ? 0.0 : mode == Mode::Additive ? 2.0 : 0.1;
  s.atoms = AtomSet(atoms);
  for (int a : held) s.atoms.set(a);
  s.tool = mode == Mode::Additive ? "head" : "T1";
  return s;
}

SearchOptions top(int k) {
  SearchOptions o;
  o.top_k = k;
  return o;
}

// A part D with waste W around it, and a closed void V inside the block: the block costs
// nothing and milling the waste is cheap, but no cutter reaches V, so no plan starts from
// the block; the part is deposited instead.
struct BlockWithAVoid {
  enum { D, W, V, Atoms };
  PlanningProblem p;
  explicit BlockWithAVoid(bool void_in_block) {
    p.atoms = {{100, true, false}, {50, false, true}, {5, false, true}};
    p.primitives = {primitive("block", Mode::Additive, Atoms, {D, W, V}, true), primitive("deposit", Mode::Additive, Atoms, {D}),
                    primitive("mill", Mode::Subtractive, Atoms, {W})};
    if (!void_in_block) p.primitives[0].atoms.set(V, false);
  }
};

TEST(StockStarts, AStockThatHoldsWhatNoRemovalClearsStartsNoPlanAndIsNeverFirst) {
  BlockWithAVoid part(true);
  const std::vector<StartProof> starts = prove_stock_starts(part.p, {});
  ASSERT_EQ(starts.size(), 1u);
  EXPECT_EQ(starts[0].primitive, 0);
  EXPECT_EQ(starts[0].proof.outcome, CoreProof::Outcome::Proven);
  EXPECT_TRUE(part.p.primitives[0].never_first);
  EXPECT_FALSE(detail::allowed(part.p, 0, true, std::vector<std::uint8_t>(3, 0)));
  const auto plans = find_plans(part.p, top(3));
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(expression(part.p, plans[0]), "deposit");
  EXPECT_NEAR(plans[0].cost, 200, 1e-9);
}

TEST(StockStarts, AStockThatStartsAPlanGivesThatPlan) {
  BlockWithAVoid part(false);
  const std::vector<StartProof> starts = prove_stock_starts(part.p, {});
  ASSERT_EQ(starts.size(), 1u);
  ASSERT_EQ(starts[0].proof.outcome, CoreProof::Outcome::Feasible);
  EXPECT_FALSE(part.p.primitives[0].never_first);
  Plan plan;
  ASSERT_TRUE(simulate(part.p, starts[0].proof.sequence, plan));
  EXPECT_TRUE(is_goal(part.p, plan.final_state));
  EXPECT_EQ(expression(part.p, plan), "(block \u2212 mill)");
}

TEST(StockStarts, WhenEveryStartIsRuledOutTheProofOfTheWholeProblemSpeaks) {
  BlockWithAVoid part(true);
  part.p.start_from_stock = true;  // only the block may start: one start, nothing to tell apart
  EXPECT_TRUE(prove_stock_starts(part.p, {}).empty());
  EXPECT_FALSE(part.p.primitives[0].never_first);
  part.p.start_from_stock = false;
  part.p.primitives[1].never_first = true;  // the deposit may not start either
  part.p.primitives[0].never_first = false;
  EXPECT_TRUE(prove_stock_starts(part.p, {}).empty());
  EXPECT_FALSE(part.p.primitives[0].never_first);
}

TEST(StockStarts, TheOptimumIsTheExhaustiveEnumeratorsWithStocksRuledOut) {
  // Random instances whose design some plan from P1 makes, with another additive
  // primitive made a raw stock: often the stock starts no plan.
  std::mt19937 rng(33);
  int ruled_out = 0, solvable = 0;
  for (int trial = 0; trial < 200; ++trial) {
    testing::VoxelProblem vp = testing::random_instance(rng, 3 + trial % 5);
    PlanningProblem& p = vp.problem;
    for (std::size_t i = 1; i < p.primitives.size(); ++i)
      if (p.primitives[i].mode == Mode::Additive && !p.primitives[i].raw_stock) {
        p.primitives[i].raw_stock = true;
        break;
      }
    const auto oracle = enumerate_plans(p, 1);
    PlanningProblem marked = p;
    const std::vector<StartProof> starts = prove_stock_starts(marked, {});
    for (const StartProof& s : starts) ruled_out += marked.primitives[std::size_t(s.primitive)].never_first;
    const auto found = find_plans(marked, top(1));
    ASSERT_EQ(found.size(), oracle.size()) << "trial " << trial;
    if (!oracle.empty()) {
      EXPECT_NEAR(found[0].cost, oracle[0].cost, 1e-9 * std::max(1.0, oracle[0].cost)) << "trial " << trial;
    }
    solvable += !oracle.empty();
  }
  EXPECT_GT(ruled_out, 20) << "the instances rule out no stock";
  EXPECT_GT(solvable, 150);
}

}  // namespace
}  // namespace hybridctl::planner
