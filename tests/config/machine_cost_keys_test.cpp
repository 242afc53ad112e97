// The machine file's costs (docs/costs.md): the `costs` section, each head's deposition
// rate and material, each tool's removal rate and wear, each raw stock's price; defaults
// when absent, the objective they imply, and every bad value reported at its place.

#include <gtest/gtest.h>

#include <string>

#include "config/machine_loader.hpp"
#include "config/summary.hpp"

namespace {

using namespace hybridctl::config;

const std::string kBase =
    "name: m\n"                                                                                 // 1
    "envelope: {X: {travel: [0, 100]}, Y: {travel: [0, 100]}, Z: {travel: [0, 300]}}\n"         // 2
    "setups: [{name: top}]\n"                                                                   // 3
    "heads: [{name: ded, process: ded-powder, bead: {width: 1.5, height: 0.75}, layer_height: 0.6, "
    "hatch_spacing: 1.05, feed: 800}]\n"                                                        // 4
    "tools: [{number: 1, type: flat, diameter: 10, step_down: 5, step_over: 4, feed: 1200}]\n"; // 5

std::string errors_of(const std::string& yaml) {
  try {
    parse_machine(yaml, "m.yaml");
  } catch (const MachineFileError& e) {
    std::string out;
    for (const auto& d : e.diagnostics()) out += d.str() + "\n";
    return out;
  }
  return "";
}

TEST(MachineCostKeys, WithoutACostsSectionPlansRankByTheOldCostFactorsAndRatesComeFromTheMotion) {
  const Machine m = parse_machine(kBase, "m.yaml");
  EXPECT_EQ(m.planning.objective, Objective::CostFactor);
  EXPECT_DOUBLE_EQ(m.heads.at(0).volume_rate(), 0.6 * 1.05 * 800);  // a layer of tracks at the feed
  EXPECT_DOUBLE_EQ(m.tools.at(0).volume_rate(), 5 * 4 * 1200);      // a full step at the feed
  EXPECT_EQ(m.heads.at(0).material.efficiency, 0.7);                // powder: the nozzle's catch
  EXPECT_EQ(m.costs.currency, "EUR");
}

TEST(MachineCostKeys, ACostsSectionMakesMoneyTheObjectiveUnlessThePlanningSaysOtherwise) {
  const Machine m = parse_machine(kBase + "costs: {currency: USD, machine_rate: 95, tool_change: 6, head_switch: 90, "
                                          "setup_change: 4, refixture: 20}\n",
                                  "m.yaml");
  EXPECT_EQ(m.planning.objective, Objective::Money);
  EXPECT_EQ(m.costs.currency, "USD");
  EXPECT_EQ(m.costs.machine_rate, 95);
  EXPECT_EQ(m.costs.tool_change, 6);
  EXPECT_EQ(m.costs.head_switch, 90);
  EXPECT_EQ(m.costs.setup_change, 4);
  EXPECT_EQ(m.costs.refixture, 20);
  const std::string text = summarize(m);
  EXPECT_NE(text.find("95 USD/h, tool change 6 s, head switch 90 s, setup change 4 s, refixture 20 min"), std::string::npos)
      << text;
  EXPECT_NE(text.find("by money"), std::string::npos) << text;
  EXPECT_EQ(parse_machine(kBase + "costs: {}\nplanning: {objective: time}\n", "m.yaml").planning.objective, Objective::Time);
}

TEST(MachineCostKeys, GivenRatesMaterialWearAndStockPricesAreKept) {
  const Machine m = parse_machine(
      "name: m\n"
      "envelope: {X: {travel: [0, 100]}, Y: {travel: [0, 100]}, Z: {travel: [0, 300]}}\n"
      "setups: [{name: top}]\n"
      "heads: [{name: arc, process: wire-arc, bead: {width: 6, height: 2}, deposition_rate: 3000, "
      "material: {density: 4.43, price_per_kg: 90, efficiency: 0.9}}]\n"
      "tools: [{number: 1, type: flat, diameter: 10, removal_rate: 8000, wear: {price: 45, life: 30}}]\n"
      "raw_stocks: [{name: plate, box: {margin: 1}, density: 4.43, price_per_kg: 25}]\n",
      "m.yaml");
  const AdditiveHead& h = m.heads.at(0);
  EXPECT_EQ(h.volume_rate(), 3000);
  EXPECT_EQ(h.material.density, 4.43);
  EXPECT_EQ(h.material.price_per_kg, 90);
  EXPECT_EQ(h.material.efficiency, 0.9);
  EXPECT_EQ(m.tools.at(0).volume_rate(), 8000);
  EXPECT_EQ(m.tools.at(0).tool_price, 45);
  EXPECT_EQ(m.tools.at(0).tool_life, 30);
  EXPECT_EQ(m.raw_stocks.at(0).price_per_kg, 25);
  EXPECT_EQ(m.raw_stocks.at(0).density, 4.43);
  // Only some material keys: the others keep the process's defaults (wire: 15 per kg).
  const Machine some = parse_machine(kBase.substr(0, kBase.find("heads:")) +
                                         "heads: [{name: w, process: wire-arc, bead: {width: 6, height: 2}, "
                                         "material: {density: 8.9}}]\n",
                                     "m.yaml");
  EXPECT_EQ(some.heads.at(0).material.price_per_kg, 15);
  EXPECT_EQ(some.heads.at(0).material.efficiency, 0.95);
}

TEST(MachineCostKeys, BadValuesAreReportedAtTheirPlace) {
  EXPECT_NE(errors_of(kBase + "costs: {machine_rate: -1}\n").find("m.yaml:6:23: costs.machine_rate: expected a non-negative rate in money per hour, got -1"), std::string::npos)
      << errors_of(kBase + "costs: {machine_rate: -1}\n");
  EXPECT_NE(errors_of(kBase + "costs: {currency: euro cents}\n").find("costs.currency: expected a short currency label"),
            std::string::npos);
  EXPECT_NE(errors_of(kBase + "costs: {refixtures: 3}\n").find("refixtures"), std::string::npos);
  EXPECT_NE(errors_of(kBase + "planning: {objective: cheapest}\n").find("planning.objective"), std::string::npos);
  const std::string head = kBase.substr(0, kBase.find("heads:")) + "heads: [{name: h, process: ded-powder, bead: {width: 2, height: 1}, ";
  EXPECT_NE(errors_of(head + "material: {efficiency: 1.5}}]\n").find("heads[0].material.efficiency: expected a fraction"),
            std::string::npos)
      << errors_of(head + "material: {efficiency: 1.5}}]\n");
  EXPECT_NE(errors_of(head + "deposition_rate: 0}]\n").find("heads[0].deposition_rate"), std::string::npos);
  const std::string tool = kBase.substr(0, kBase.find("tools:")) + "tools: [{number: 1, type: flat, diameter: 10, ";
  EXPECT_NE(errors_of(tool + "wear: {life: 0}}]\n").find("tools[0].wear.life"), std::string::npos);
  EXPECT_NE(errors_of(tool + "removal_rate: -3}]\n").find("tools[0].removal_rate"), std::string::npos);
  EXPECT_NE(errors_of(kBase + "raw_stocks: [{name: s, box: {margin: 1}, price_per_kg: -2}]\n").find("raw_stocks[0].price_per_kg"),
            std::string::npos);
}

}  // namespace
