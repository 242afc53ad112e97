// The report's toolpaths: each plan's actions as toolpaths::export_plan makes them against
// the planned states, whether or not other plans begin with the same actions (the report
// exports such shared actions once), and a plan the machine cannot make keeps its reason.

#include "report/report_toolpaths.hpp"

#include <gtest/gtest.h>

#include "../validation/validation_cases.hpp"
#include "plan/plan_file.hpp"

namespace hybridctl::report {
namespace {

using geometry::Solid;

using validation::cases::Case;
using validation::cases::machine;

// A block from a raw stock with two overlapping steps milled from above, by the 10 mm flat
// (P2) and the 3 mm flat (P3), in three plans: P2 then P3, P2 alone, P3 then P2.
plan::PlanFile stepped_block() {
  Case c(0.5);
  const Solid raw = c.box({{0, 0, 0}, {30, 20, 10}});
  const Solid step_a = c.box({{20, -5, 6}, {35, 25, 15}}), step_b = c.box({{-5, -5, 8}, {24, 25, 15}});
  c.file.design = subtract(subtract(raw, step_a), step_b);
  const int s = c.stock(raw), a = c.mill(step_a, 1), b = c.mill(step_b, 3);
  c.file.plans = {c.plan({s, a, b}), c.plan({s, a}), c.plan({s, b, a})};
  for (std::size_t k = 0; k < c.file.plans.size(); ++k)
    for (plan::PlanFileAction& action : c.file.plans[k].actions) action.cost = double(k + 1);
  return c.file;
}

std::vector<std::vector<Solid>> states_of(const plan::PlanFile& file) {
  std::vector<std::vector<Solid>> out;
  for (const plan::PlanFilePlan& plan : file.plans) out.push_back(plan::plan_states(file, plan));
  return out;
}

void expect_same(const ActionPath& a, const ActionPath& b, const std::string& where) {
  EXPECT_EQ(a.step, b.step) << where;
  EXPECT_EQ(a.primitive, b.primitive) << where;
  EXPECT_EQ(a.makes_gcode, b.makes_gcode) << where;
  EXPECT_EQ(a.points, b.points) << where;
  EXPECT_EQ(a.kinds, b.kinds) << where;
  EXPECT_EQ(a.layers, b.layers) << where;
  EXPECT_EQ(a.cycle_s, b.cycle_s) << where;
}

TEST(ReportToolpaths, EachPlanIsAsIfExportedAloneThoughPlansShareTheirFirstActions) {
  const plan::PlanFile file = stepped_block();
  const std::vector<PlanPaths> all = plan_paths(file, states_of(file), machine());
  ASSERT_EQ(all.size(), 3u);
  for (std::size_t k = 0; k < file.plans.size(); ++k) {
    plan::PlanFile alone = file;
    alone.plans = {file.plans[k]};
    const std::vector<PlanPaths> one = plan_paths(alone, states_of(alone), machine());
    ASSERT_EQ(one.size(), 1u);
    EXPECT_TRUE(all[k].error.empty()) << all[k].error;
    ASSERT_EQ(all[k].actions.size(), file.plans[k].actions.size());
    ASSERT_EQ(one[0].actions.size(), all[k].actions.size());
    for (std::size_t a = 0; a < all[k].actions.size(); ++a)
      expect_same(all[k].actions[a], one[0].actions[a], "plan " + std::to_string(k + 1) + " action " + std::to_string(a + 1));
    EXPECT_EQ(all[k].line_positions.size(), one[0].line_positions.size());
  }
  // The stock is clamped, each step milled: the mills make G-code that cuts.
  EXPECT_FALSE(all[0].actions[0].makes_gcode);
  EXPECT_TRUE(all[0].actions[1].makes_gcode);
  EXPECT_GT(all[0].actions[1].process_length, 0);
  EXPECT_GT(all[0].actions[2].process_length, 0);
  // P3 after P2 is not P3 from the stock: the same primitive meets other material.
  EXPECT_EQ(all[0].actions[2].step, 3);
  EXPECT_EQ(all[2].actions[1].step, 2);
  EXPECT_NE(all[0].actions[2].points, all[2].actions[1].points);
  EXPECT_FALSE(all[0].line_positions.empty());
}

TEST(ReportToolpaths, APlanTheMachineCannotMakeKeepsItsReasonAndTheOthersTheirPaths) {
  plan::PlanFile file = stepped_block();
  file.primitives[2].setup = "no-such-setup";
  const std::vector<PlanPaths> all = plan_paths(file, states_of(file), machine());
  ASSERT_EQ(all.size(), 3u);
  EXPECT_NE(all[0].error.find("no-such-setup"), std::string::npos) << all[0].error;
  EXPECT_TRUE(all[0].actions.empty());
  EXPECT_TRUE(all[1].error.empty()) << all[1].error;
  EXPECT_EQ(all[1].actions.size(), 2u);
  EXPECT_FALSE(all[2].error.empty());
}

}  // namespace
}  // namespace hybridctl::report
