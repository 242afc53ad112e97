// The ways of making a part compared (planner/pipeline/ways_compared.hpp): the machine
// without its heads mills from stock, without its tools deposits only; each way's best plan
// in words, with its machine time and money as the plans are ranked, or why it has none.

#include <gtest/gtest.h>

#include "planner/pipeline/ways_compared.hpp"

namespace hybridctl::planner {
namespace {

Primitive primitive(const std::string& label, PrimitiveKind kind, Mode mode) {
  Primitive p;
  p.label = label;
  p.kind = kind;
  p.mode = mode;
  return p;
}

// A result whose best plan runs `steps` of a stock, a deposit and a removal, costing
// `money` by the estimate or, re-ranked by its toolpaths, `toolpath_money`.
PlanningResult planned(std::vector<int> steps, double money, double minutes, double toolpath_money = 0) {
  PlanningResult r;
  r.objective = config::Objective::Money;
  r.currency = "EUR";
  r.verdict.outcome = Verdict::Outcome::Manufacturable;
  r.primitives = {primitive("raw stock plate-12 (plate)", PrimitiveKind::RawStock, Mode::Additive),
                  primitive("O-AM lwd from +Z (top)", PrimitiveKind::OAm, Mode::Additive),
                  primitive("SM-max T1 from +Z (top)", PrimitiveKind::SmMax, Mode::Subtractive)};
  Plan plan;
  for (const int s : steps) plan.steps.push_back({s, 0, 0});
  plan.cost = money;
  r.plans.push_back(plan);
  PlanEstimate e;
  e.total = {minutes, money};
  r.estimates.push_back(e);
  if (toolpath_money > 0) {
    r.ranked_by_toolpaths = true;
    r.toolpath_costs = {toolpath_money};
    r.toolpath_minutes = {{0, 70, 20}};
    r.cycle_times = {plan::CycleTime{90 * 60.0, "1 h 30 min 00 s: motion 1 h 30 min 00 s"}};
  }
  return r;
}

PlanningResult refused(const std::string& why) {
  PlanningResult r;
  r.verdict.outcome = Verdict::Outcome::NotManufacturable;
  r.verdict.summary = why;
  return r;
}

config::Machine machine_with(bool head, bool tool) {
  config::Machine m;
  m.name = "cell";
  if (head) {
    config::AdditiveHead h;
    h.name = "lwd";
    m.heads.push_back(h);
  }
  if (tool) {
    config::CuttingTool t;
    t.number = 1;
    m.tools.push_back(t);
  }
  return m;
}

TEST(WaysCompared, MillsOnTheMachineWithoutItsHeadsAndDepositsOnItWithoutItsTools) {
  std::vector<config::Machine> asked;
  const WaysCompared c = compare_ways(machine_with(true, true), planned({0, 1, 2}, 240, 52, 441.17),
                                      [&](const config::Machine& on) {
                                        asked.push_back(on);
                                        return on.heads.empty() ? planned({0, 2, 2}, 763.05, 109) : refused("1 atom straddles the design");
                                      });
  ASSERT_EQ(asked.size(), 2u);
  EXPECT_TRUE(asked[0].heads.empty());
  EXPECT_EQ(asked[0].tools.size(), 1u);
  EXPECT_EQ(asked[1].heads.size(), 1u);
  EXPECT_TRUE(asked[1].tools.empty());
  ASSERT_EQ(c.ways.size(), 3u);
  // The hybrid plan as ranked: by its toolpaths' times, which re-ranked the plans; its
  // machine time its program's cycle time.
  EXPECT_EQ(c.ways[0].plan, "from plate-12 (plate), 1 deposit, 1 removal");
  EXPECT_DOUBLE_EQ(c.ways[0].money, 441.17);
  EXPECT_DOUBLE_EQ(c.ways[0].minutes, 90);
  EXPECT_TRUE(c.ways[0].cycle_time);
  EXPECT_EQ(c.ways[1].plan, "from plate-12 (plate), 2 removals");
  EXPECT_DOUBLE_EQ(c.ways[1].money, 763.05);
  EXPECT_FALSE(c.ways[2].planned);
  EXPECT_EQ(c.ways[2].why_not, "no plan: 1 atom straddles the design");
  const std::string text = ways_compared_text(c);
  EXPECT_NE(text.find("hybrid             from plate-12 (plate), 1 deposit, 1 removal"), std::string::npos) << text;
  EXPECT_NE(text.find("1 h 30 min 00 s  441.17 EUR"), std::string::npos) << text;
  EXPECT_NE(text.find("deposited only     no plan: 1 atom straddles the design"), std::string::npos) << text;
  EXPECT_NE(text.find("the hybrid plan costs 42 % less than the best plan milled from stock"), std::string::npos) << text;
}

TEST(WaysCompared, AWayTheMachineCannotTakeIsNotPlanned) {
  int asked = 0;
  const WaysCompared c = compare_ways(machine_with(false, true), planned({0, 2}, 300, 60), [&](const config::Machine&) {
    ++asked;
    return planned({0, 2}, 300, 60);
  });
  EXPECT_EQ(asked, 1);
  EXPECT_EQ(c.ways[2].why_not, "the machine has no head");
  // No saving to claim where the hybrid plan is the milling plan's equal.
  EXPECT_NE(ways_compared_text(c).find("costs 0 % less"), std::string::npos);
}

}  // namespace
}  // namespace hybridctl::planner
