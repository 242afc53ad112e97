// What actions cost in machine time and money (planner/costing/costs.hpp, docs/costs.md).

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "planner/costing/costs.hpp"

namespace {

using namespace hybridctl;
using namespace hybridctl::planner;

// Parsed on first use: the loader's tables are static too, and their order across files is not.
const config::Machine& machine() {
  static const config::Machine m = config::parse_machine(
    "name: m\n"
    "envelope: {X: {travel: [0, 400]}, Y: {travel: [0, 300]}, Z: {travel: [0, 300]}}\n"
    "setups: [{name: top}, {name: bottom, approach: -Z, manual_refixture: true}, {name: side, approach: +X}]\n"
    "heads: [{name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75}, layer_height: 0.6, "
    "hatch_spacing: 1.05, feed: 800, material: {density: 8, price_per_kg: 50, efficiency: 0.5}}]\n"
    "tools: [{number: 1, type: flat, diameter: 10, step_down: 5, step_over: 4, feed: 1200, wear: {price: 90, life: 60}},\n"
    "        {number: 2, type: ball, diameter: 6}]\n"
    "raw_stocks: [{name: plate, box: {margin: 1}, density: 8, price_per_kg: 5}]\n"
    "costs: {machine_rate: 120, tool_change: 6, head_switch: 60, setup_change: 12, refixture: 15}\n",
    "m.yaml");
  return m;
}

Primitive deposit(const std::string& setup = "top") {
  Primitive p;
  p.kind = PrimitiveKind::UAm;
  p.mode = Mode::Additive;
  p.capability = "ded";
  p.setup = setup;
  return p;
}

Primitive removal(int tool, const std::string& setup = "top") {
  Primitive p;
  p.kind = PrimitiveKind::SmMax;
  p.mode = Mode::Subtractive;
  p.capability = "T" + std::to_string(tool);
  p.tool_number = tool;
  p.setup = setup;
  return p;
}

TEST(Costing, ADepositTakesItsVolumeOverTheHeadsRateAndPaysForTheMaterialItWastes) {
  const Estimate e = per_mm3(machine(), deposit());
  const double rate = 0.6 * 1.05 * 800;  // mm³/min
  EXPECT_DOUBLE_EQ(e.minutes, 1 / rate);
  // 2 per minute of machine, and 8 g/cm³ at 50 per kg of which half ends in the part.
  EXPECT_DOUBLE_EQ(e.money, 2 / rate + 8e-6 * 50 / 0.5);
}

TEST(Costing, ARemovalTakesItsVolumeOverTheToolsRateAndWearsTheTool) {
  const Estimate e = per_mm3(machine(), removal(1));
  EXPECT_DOUBLE_EQ(e.minutes, 1.0 / 24000);
  EXPECT_DOUBLE_EQ(e.money, (2.0 + 90.0 / 60) / 24000);  // machine time and a tool's life per minute
}

TEST(Costing, ARawStockCostsItsMaterialAndNoTime) {
  Primitive stock;
  stock.kind = PrimitiveKind::RawStock;
  stock.capability = "plate";
  const Estimate e = per_mm3(machine(), stock);
  EXPECT_EQ(e.minutes, 0);
  EXPECT_DOUBLE_EQ(e.money, 8e-6 * 5);
}

TEST(Costing, ChangesCostToolChangeHeadSwitchSetupChangeOrTheOperatorsRefixture) {
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1), removal(1)).minutes, 0);
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1), removal(2)).minutes, 6.0 / 60);
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1), deposit()).minutes, (6.0 + 60.0) / 60);
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1, "top"), removal(1, "side")).minutes, 12.0 / 60);
  // Re-clamping is paid into the hand-fixtured setup and out of it again.
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1, "top"), removal(1, "bottom")).minutes, 15);
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1, "bottom"), removal(1, "side")).minutes, 15);
  EXPECT_DOUBLE_EQ(change_between(machine(), removal(1, "top"), removal(1, "bottom")).money, 30);
}

TEST(Costing, APlansEstimateIsItsStepsWithTheChangesBeforeThem) {
  const std::vector<Primitive> prims = {removal(1), deposit(), removal(1, "bottom")};
  Plan plan;
  plan.steps = {{0, 24000, 0}, {1, 504, 0}, {2, 2400, 0}};
  const PlanEstimate e = estimate_plan(machine(), prims, plan);
  ASSERT_EQ(e.steps.size(), 3u);
  EXPECT_DOUBLE_EQ(e.steps[0].minutes, 1);
  EXPECT_DOUBLE_EQ(e.steps[1].minutes, 1 + (6.0 + 60.0) / 60);
  EXPECT_DOUBLE_EQ(e.steps[2].minutes, 0.1 + (6.0 + 60.0) / 60 + 15);
  EXPECT_DOUBLE_EQ(e.total.minutes, e.steps[0].minutes + e.steps[1].minutes + e.steps[2].minutes);
  EXPECT_DOUBLE_EQ(e.total.money, e.steps[0].money + e.steps[1].money + e.steps[2].money);
}

TEST(Costing, TheObjectiveChoosesTheSearchsUnits) {
  const Primitive d = deposit();
  EXPECT_DOUBLE_EQ(objective_per_mm3(machine(), config::Objective::Time, d), per_mm3(machine(), d).minutes);
  EXPECT_DOUBLE_EQ(objective_per_mm3(machine(), config::Objective::Money, d), per_mm3(machine(), d).money);
  Primitive factor = d;
  factor.cost_per_mm3 = 2.5;
  EXPECT_EQ(objective_per_mm3(machine(), config::Objective::CostFactor, factor), 2.5);
  const FixedCosts minutes = objective_fixed_costs(machine(), config::Objective::Time);
  EXPECT_DOUBLE_EQ(minutes.tool_change, 0.1);
  EXPECT_DOUBLE_EQ(minutes.mode_switch, 1);
  EXPECT_DOUBLE_EQ(minutes.setup_change, 0.2);
  EXPECT_DOUBLE_EQ(minutes.refixture, 15);
  EXPECT_DOUBLE_EQ(objective_fixed_costs(machine(), config::Objective::Money).refixture, 30);
  EXPECT_TRUE(refixture_setup(machine(), removal(1, "bottom")));
  EXPECT_FALSE(refixture_setup(machine(), removal(1, "side")));
}

TEST(Costing, DurationsAndMoneyReadAsAShopWritesThem) {
  EXPECT_EQ(duration_text(0.75), "45 s");
  EXPECT_EQ(duration_text(12.2), "12 min");
  EXPECT_EQ(duration_text(113.4), "1 h 53 min");
  EXPECT_EQ(money_text(245.104, "EUR"), "245.10 EUR");
}

}  // namespace
