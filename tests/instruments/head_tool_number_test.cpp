// The T number of a head: its tool_number when given, otherwise 100 + its index in the
// machine's heads; the machine loader, plan export and the simulated machine all number
// heads so.

#include "instruments/bead.hpp"

#include <gtest/gtest.h>

#include "config/machine_loader.hpp"
#include "geometry/shapes.hpp"
#include "plan/plan_file.hpp"
#include "sim/executor.hpp"
#include "toolpaths/plan_export.hpp"

namespace hybridctl::instruments {
namespace {

config::Machine example_machine() { return config::load_machine("examples/machines/hybrid-3axis.yaml"); }

TEST(HeadToolNumber, AGivenNumberWinsOtherwiseOneHundredPlusTheIndex) {
  config::Machine m;
  m.heads.resize(3);
  m.heads[1].tool_number = 7;
  EXPECT_EQ(head_tool_number(m, 0), 100);
  EXPECT_EQ(head_tool_number(m, 1), 7);
  EXPECT_EQ(head_tool_number(m, 2), 102);
  EXPECT_EQ(head_tool_number(m.heads[0], 55), 55);
  EXPECT_EQ(head_tool_number(m.heads[1], 55), 7);
}

TEST(HeadToolNumber, TheMachineLoaderNumbersHeadsTheSameWay) {
  const config::Machine m = example_machine();
  ASSERT_FALSE(m.heads.empty());
  for (std::size_t i = 0; i < m.heads.size(); ++i) {
    EXPECT_EQ(m.heads[i].tool_number, head_tool_number(m, i));
    EXPECT_EQ(m.heads[i].tool_number, config::kDefaultHeadToolNumberBase + int(i)) << "the example gives no tool_number";
  }
}

// A plan of one deposition by head `head` of a small block, for machine `m`.
plan::PlanFile one_deposition(const config::Machine& m, const std::string& head) {
  plan::PlanFile f;
  f.machine_name = m.name;
  f.lattice = {1.0, {0, 0, 0}};
  f.domain = {{0, 0, 0}, {20, 20, 10}};
  plan::PlanFilePrimitive p;
  p.name = "P1";
  p.label = "U-AM " + head;
  p.kind = config::PrimitiveKind::UAm;
  p.mode = config::Mode::Additive;
  p.capability = head;
  p.setup = m.setups.front().name;
  p.region = geometry::make_box(f.lattice, {{2, 2, 0}, {12, 12, 3}});
  f.primitives.push_back(p);
  plan::PlanFilePlan plan;
  plan.actions.push_back({0, p.region.volume(), 1});
  f.plans.push_back(plan);
  return f;
}

TEST(HeadToolNumber, PlanExportAndTheSimulatedMachineSelectAHeadByTheSameNumber) {
  config::Machine m = example_machine();
  // A machine built by hand leaves the numbers at 0: both fall back to 100 + the index.
  for (auto& h : m.heads) h.tool_number = 0;
  for (std::size_t i = 0; i < m.heads.size(); ++i) {
    SCOPED_TRACE(m.heads[i].name);
    const int number = head_tool_number(m, i);
    const plan::PlanFile f = one_deposition(m, m.heads[i].name);
    const toolpaths::PlanExport e = toolpaths::export_plan(f, f.plans.front(), m);
    ASSERT_EQ(e.actions.size(), 1u);
    ASSERT_TRUE(e.actions[0].makes_gcode);
    EXPECT_EQ(e.actions[0].program.path.tool_number, number);

    sim::ProgramExecutor executor(m, "heads.ngc");
    const sim::LineOutcome changed = executor.execute_line("T" + std::to_string(number) + " M6", 1);
    EXPECT_EQ(changed.stop, sim::Stop::None) << changed.message;
  }
  sim::ProgramExecutor executor(m, "heads.ngc");
  EXPECT_EQ(executor.execute_line("T" + std::to_string(100 + int(m.heads.size())) + " M6", 1).stop,
            sim::Stop::ToolNotInMagazine);
}

}  // namespace
}  // namespace hybridctl::instruments
