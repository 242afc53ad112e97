// The estimate checked against the toolpaths (planner/costing/toolpath_rank.hpp, docs/costs.md):
// where an action's estimate is more than a quarter off its toolpath's cycle time, the
// plans are ranked by their cost with the toolpaths' times.

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "planner/costing/toolpath_rank.hpp"
#include "planner/pipeline/rank.hpp"

namespace {

using namespace hybridctl;
using namespace hybridctl::planner;

const config::Machine& machine() {
  static const config::Machine m = config::parse_machine(
      "name: m\n"
      "envelope: {X: {travel: [0, 400]}, Y: {travel: [0, 300]}, Z: {travel: [0, 300]}}\n"
      "setups: [{name: top}]\n"
      "heads: [{name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75}, deposition_rate: 100}]\n"
      "tools: [{number: 1, type: flat, diameter: 10, removal_rate: 1000, wear: {price: 0, life: 60}}]\n"
      "costs: {machine_rate: 60, tool_change: 0, head_switch: 0, setup_change: 0, refixture: 0}\n",
      "m.yaml");
  return m;
}

// Two plans of one step each, deposit (P1) and mill (P2): 1,000 mm³ each, so that the
// estimate makes the deposit 10 min and the milling 1 min; in minutes, milling ranks first.
PlanningResult two_plans() {
  PlanningResult r;
  r.objective = config::Objective::Time;
  Primitive deposit;
  deposit.kind = PrimitiveKind::UAm;
  deposit.mode = Mode::Additive;
  deposit.capability = "ded";
  deposit.setup = "top";
  Primitive mill;
  mill.kind = PrimitiveKind::SmMax;
  mill.mode = Mode::Subtractive;
  mill.capability = "T1";
  mill.tool_number = 1;
  mill.setup = "top";
  r.primitives = {deposit, mill};
  Plan milled, deposited;
  milled.steps = {{1, 1000, 1.0}};
  milled.cost = 1;
  deposited.steps = {{0, 1000, 10.0}};
  deposited.cost = 10;
  r.plans = {milled, deposited};
  r.deviations.resize(2);
  r.estimates = {estimate_plan(machine(), r.primitives, milled), estimate_plan(machine(), r.primitives, deposited)};
  return r;
}

TEST(ToolpathRank, AnEstimateIsOffWhenItMissesTheToolpathByMoreThanAQuarter) {
  EXPECT_FALSE(estimate_off(10, 12.4));
  EXPECT_TRUE(estimate_off(10, 12.6));
  EXPECT_TRUE(estimate_off(10, 7.4));
  EXPECT_FALSE(estimate_off(0.2, 0.9));  // under a minute either way: lifts and rapids, not a wrong rate
  EXPECT_TRUE(estimate_off(0.2, 1.5));
}

TEST(ToolpathRank, PlansKeepTheSearchsOrderWhileTheEstimatesHold) {
  PlanningResult r = two_plans();
  r.toolpath_minutes = {{1.1}, {11}};
  rank_by_toolpaths(machine(), r);
  EXPECT_FALSE(r.ranked_by_toolpaths);
  EXPECT_EQ(r.estimates_off, 0);
  EXPECT_EQ(r.plans[0].steps[0].primitive, 1);
  EXPECT_EQ(r.search_rank, (std::vector<std::size_t>{0, 1}));
}

TEST(ToolpathRank, AFarOffEstimateRanksThePlansByTheirToolpathsTimes) {
  PlanningResult r = two_plans();
  // The milling's toolpath clears air for 30 min: the deposit is cheaper after all.
  r.toolpath_minutes = {{30}, {11}};
  rank_by_toolpaths(machine(), r);
  ASSERT_TRUE(r.ranked_by_toolpaths);
  EXPECT_EQ(r.estimates_off, 1);
  EXPECT_EQ(r.plans[0].steps[0].primitive, 0);
  EXPECT_EQ(r.search_rank, (std::vector<std::size_t>{1, 0}));
  EXPECT_EQ(r.toolpath_minutes[0], std::vector<double>{11});
  EXPECT_DOUBLE_EQ(r.toolpath_costs[0], 11);
  EXPECT_DOUBLE_EQ(r.toolpath_costs[1], 30);
  EXPECT_DOUBLE_EQ(r.estimates[0].total.minutes, 10);  // the estimates travel with their plans
}

TEST(ToolpathRank, CostFactorsAreNotTimesSoTheirRankingStandsAndTheEstimatesOffAreCounted) {
  PlanningResult r = two_plans();
  r.objective = config::Objective::CostFactor;
  r.toolpath_minutes = {{30}, {11}};
  rank_by_toolpaths(machine(), r);
  EXPECT_FALSE(r.ranked_by_toolpaths);
  EXPECT_EQ(r.estimates_off, 1);
  EXPECT_EQ(r.plans[0].steps[0].primitive, 1);
}

TEST(ToolpathRank, InMoneyTheToolpathsTimeIsPricedAtTheMachinesRateAndTheMaterialStays) {
  PlanningResult r = two_plans();
  r.objective = config::Objective::Money;
  const double material = 1000 * 7.9e-6 * 40 / 0.7;  // the head's default powder
  r.plans[1].steps[0].cost = r.estimates[1].total.money;
  EXPECT_DOUBLE_EQ(cost_with_toolpaths(machine(), r, r.plans[1], {12}), 12 + material);
  EXPECT_DOUBLE_EQ(cost_with_toolpaths(machine(), r, r.plans[1], {}), 10 + material);  // unknown: the estimate
}

}  // namespace
