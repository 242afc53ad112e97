// Plans priced as a shop prices them (docs/costs.md): `plan` ranks by money or minutes,
// prints each plan and action in both, and chooses between a block and a plate stock by
// what they cost.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>

#include "shell.hpp"

namespace {

namespace fs = std::filesystem;

using hybridctl::cli_testing::Outcome;
using hybridctl::cli_testing::slurp;

class Costs : public hybridctl::cli_testing::DirectoryTest {
 protected:
  Costs() : DirectoryTest("costs") {}
};

const std::string kSource = HYBRIDCTL_SOURCE_DIR;
const std::string kTitanium = kSource + "/examples/machines/wire-ded-ti.yaml";
const std::string kBossPlate = kSource + "/examples/parts/boss-plate.stl";
const std::string kFlangedHub = kSource + "/examples/parts/flanged-hub.stl";
const std::string kHybrid = kSource + "/examples/machines/hybrid-3axis.yaml";

struct Priced {
  std::string expression;
  double money = 0;
  std::string first_step;  // the line of its first action
};

// Plan 1 of `plan`'s printout: "  1. EXPR  cost 195.79 EUR, ..." and its first action.
Priced best_plan(const std::string& out) {
  static const std::regex plan("\\n  1\\. (\\S[^\\n]*)  cost ([0-9.]+) EUR[^\\n]*\\n[^\\n]*\\n[^\\n]*\\n     1\\) ([^\\n]*)");
  std::smatch m;
  if (!std::regex_search(out, m, plan)) return {};
  return {m[1], std::stod(m[2]), m[3]};
}

// A plate of the base's thickness in the machine file, titanium's prices: the best plan
// starts from the plate, deposits only the boss (to size, or with its allowance above the
// plate's top, milled to size after) and mills the plate's margin. Without the plate the best plan mills the part from a block, and
// costs more in money and in minutes: both are printed in the same run.
//
// The search's choice alone (validation judges the parts against the STL, a different
// question, docs/verification.md).
TEST_F(Costs, TheBossIsDepositedOnAPlateWhenTheRatesMakeThatCheaperThanMillingItFromABlock) {
  const Outcome on_plate = run_hybridctl({"plan", kBossPlate, "--machine", kTitanium, "--top", "1", "--no-validate"});
  ASSERT_EQ(on_plate.exit_code, 0) << on_plate.err << on_plate.out;
  const Priced hybrid = best_plan(on_plate.out);
  EXPECT_NE(hybrid.first_step.find("raw stock plate-12 (plate)"), std::string::npos) << on_plate.out;
  const std::regex deposit("\\n     [0-9]\\) P[0-9]+ +[OU]-AM lwd from \\+Z \\(top\\)[^\\n]* +deposit +([0-9.]+) mm");
  std::smatch d;
  ASSERT_TRUE(std::regex_search(on_plate.out, d, deposit)) << on_plate.out;
  // The boss is 75,400 mm³; what is deposited is the boss and its allowance, not the plate.
  EXPECT_GT(std::stod(d[1]), 75000);
  EXPECT_LT(std::stod(d[1]), 110000);

  std::string yaml = slurp(kTitanium);
  const std::size_t plate = yaml.find("  - name: plate-12");
  ASSERT_NE(plate, std::string::npos);
  yaml.erase(plate, yaml.find("\ncosts:") - plate);
  std::ofstream(dir_ / "block-only.yaml") << yaml;
  const Outcome from_block =
      run_hybridctl({"plan", kBossPlate, "--machine", (dir_ / "block-only.yaml").string(), "--top", "1", "--no-validate"});
  ASSERT_EQ(from_block.exit_code, 0) << from_block.err << from_block.out;
  const Priced milled = best_plan(from_block.out);
  EXPECT_NE(milled.first_step.find("raw stock block (box)"), std::string::npos) << from_block.out;
  EXPECT_LT(hybrid.money, milled.money) << on_plate.out << from_block.out;
}

// The objective is the user's: --objective time ranks by minutes and prints them; the
// estimate in minutes and money is printed whatever the objective, and plan.json carries both.
TEST_F(Costs, TheObjectiveIsTheUsersAndEveryPlanCarriesItsMinutesAndMoney) {
  const Outcome r = run_hybridctl({"plan", kFlangedHub, "--machine", kHybrid, "--top", "1", "--objective", "time", "-o",
                                   (dir_ / "plan").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("objective   time: plans cost their minutes of machine time"), std::string::npos) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\n  1\\. [^\\n]*  cost [0-9.]+ min, proven optimal"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\n     estimate: [^\\n]* of machine time, [0-9.]+ EUR"))) << r.out;
  const std::string json = slurp(dir_ / "plan" / "plan.json");
  EXPECT_NE(json.find("\"objective\": \"time\""), std::string::npos);
  EXPECT_NE(json.find("\"currency\": \"EUR\""), std::string::npos);
  EXPECT_NE(json.find("\"minutes\":"), std::string::npos);
  EXPECT_NE(json.find("\"money\":"), std::string::npos);
  // Proven by execution, each action also carries its program's motion, and the plan its
  // program's cycle time.
  EXPECT_TRUE(std::regex_search(json, std::regex("\"toolpath_minutes\": [0-9]"))) << json.substr(0, 2000);
  EXPECT_TRUE(std::regex_search(json, std::regex("\"cycle_time\": \\{"))) << json.substr(0, 2000);
  EXPECT_TRUE(std::regex_search(r.out, std::regex("; motion [0-9]"))) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\n     cycle time: [0-9][^\n]*: motion "))) << r.out;
  const Outcome bad = run_hybridctl({"plan", kBossPlate, "--machine", kTitanium, "--objective", "cheapest"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--objective"), std::string::npos) << bad.err;
}

}  // namespace
