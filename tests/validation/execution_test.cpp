// Validation by execution (docs/validation.md) on small hand-made plans for the bundled
// hybrid machine: each reason a plan is rejected for shows up on a case made to have it,
// located by action, line and place; a plan that makes its part has none; and the search,
// given validation as its accept hook, goes on past a rejected plan to the next valid one.

#include "validation/execution.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "../planner/planner_fixtures.hpp"
#include "validation_cases.hpp"
#include "validation/plan_validator.hpp"

namespace hybridctl::validation {
namespace {

using geometry::Box3;
using geometry::Solid;
using cases::Case;
using cases::machine;

std::vector<std::string> kinds(const Execution& run) {
  std::vector<std::string> out;
  for (const auto& r : run.reasons) out.push_back(r.kind);
  return out;
}

const plan::RejectionReason* first_of(const Execution& run, const std::string& kind) {
  for (const auto& r : run.reasons)
    if (r.kind == kind) return &r;
  return nullptr;
}

bool has(const Execution& run, const std::string& kind) { return first_of(run, kind) != nullptr; }

// The reasons, and per action what its toolpath did, for failure messages.
std::string all_reasons(const Execution& run) {
  std::string out = describe_reasons(run.reasons, 100);
  for (const toolpaths::ExportedAction& a : run.exported.actions) {
    out += "action " + std::to_string(a.step) + " " + a.primitive + ": " + a.note +
           (a.makes_gcode ? std::to_string(a.program.path.moves.size()) + " moves" : std::string()) + "\n";
    for (const std::string& w : a.program.path.warnings) out += "  warning: " + w + "\n";
  }
  return out;
}

// Whether the action's toolpath says it left an overhang out (docs/toolpaths.md).
bool overhang_not_deposited(const toolpaths::ExportedAction& action) {
  for (const std::string& w : action.program.path.warnings)
    if (w.find("overhang") != std::string::npos && w.find("not deposited") != std::string::npos) return true;
  return false;
}

// A block milled from a raw stock with the 10 mm flat: an open step the tool reaches.
TEST(Execution, APlanThatMakesItsPartHasNoReason) {
  Case c(0.5);
  const Solid raw = c.box({{0, 0, 0}, {30, 20, 10}});
  c.file.design = subtract(raw, c.box({{15, -5, 5}, {35, 25, 15}}));
  const int s = c.stock(raw);
  const int m = c.mill(c.box({{15, -5, 5}, {35, 25, 15}}), 1);
  const Execution run = execute_plan(c.file, c.plan({s, m}), machine());
  EXPECT_TRUE(run.proven()) << all_reasons(run);
  EXPECT_GT(run.program.lines.size(), 10u);
  EXPECT_TRUE(run.deviation.within_tolerance);
  EXPECT_EQ(run.report.gouge, 0);
}

// The same from the bottom setup: the part turned over, the step milled from below.
TEST(Execution, APlanMilledFromBelowMakesItsPartToo) {
  Case c(0.5);
  const Solid raw = c.box({{0, 0, 2}, {30, 20, 12}});
  c.file.design = subtract(raw, c.box({{15, -5, -5}, {35, 25, 7}}));
  const int s = c.stock(raw);
  const int m = c.mill(c.box({{15, -5, -5}, {35, 25, 7}}), 1, "bottom");
  const Execution run = execute_plan(c.file, c.plan({s, m}), machine());
  EXPECT_TRUE(run.proven()) << all_reasons(run);
  EXPECT_EQ(run.report.gouge, 0);
}

// A hybrid plan from the bottom setup: the mill takes a step out of the design on purpose
// (an SM-cons region: only the tool's body keeps clear of the design) and the head builds
// it again. Cutting what the plan builds again is no gouge; the part as built is judged.
TEST(Execution, DesignMilledFromBelowAndDepositedAgainIsNoGouge) {
  Case c(1.0);
  const Solid raw = c.box({{5, 5, 2}, {35, 25, 12}});
  c.file.design = raw;
  const int s = c.stock(raw);
  const int m = c.mill(c.box({{20, 0, -5}, {40, 30, 7}}), 1, "bottom");
  const int d = c.deposit(c.box({{20, 5, 2}, {35, 25, 7}}), "bottom");
  const Execution run = execute_plan(c.file, c.plan({s, m, d}), machine());
  EXPECT_FALSE(has(run, "gouge")) << all_reasons(run);
  EXPECT_EQ(run.report.gouge, 0);
  EXPECT_GT(run.report.removed, 0.9 * 15 * 20 * 5) << "the step was milled out of the design";
  // Thin voids where beads meet stay (docs/export.md: at most 2 % of a deposit).
  EXPECT_LT(run.deviation.under_volume, 0.02 * 15 * 20 * 5) << all_reasons(run);

  // Without the deposit the step stays missing: the part is wrong, and says so as such.
  const Execution milled = execute_plan(c.file, c.plan({s, m}), machine());
  EXPECT_FALSE(has(milled, "gouge")) << all_reasons(milled);
  EXPECT_TRUE(has(milled, "missing_material")) << all_reasons(milled);
}

TEST(Execution, AMissingFeatureIsMissingMaterial) {
  Case c(1.0);
  const Solid plate = c.box({{5, 5, 0}, {25, 25, 4}});
  c.file.design = unite(plate, c.box({{14, 7, 4}, {17, 23, 12}}));  // a 3 mm fin the plan leaves out
  const Execution run = execute_plan(c.file, c.plan({c.deposit(plate)}), machine());
  ASSERT_TRUE(has(run, "missing_material")) << all_reasons(run);
  EXPECT_GT(run.deviation.under_volume, 0.8 * 3 * 16 * 8);
  EXPECT_FALSE(run.deviation.within_tolerance);
}

// A fin thinner than twice the tolerance, left out: none of its voxels is deep inside the
// design, yet its tip is 8 mm from the part made. The reason says how far, and where.
TEST(Execution, AThinFinLeftOutIsMissingMaterialAtItsTip) {
  Case c(1.0);
  const Solid plate = c.box({{5, 5, 0}, {25, 25, 4}});
  c.file.design = unite(plate, c.box({{14, 7, 4}, {15, 23, 12}}));  // 1 mm thick, 8 mm tall
  const Execution run = execute_plan(c.file, c.plan({c.deposit(plate)}), machine());
  const plan::RejectionReason* r = first_of(run, "missing_material");
  ASSERT_NE(r, nullptr) << all_reasons(run);
  const auto at = r->message.find("lies up to ");
  ASSERT_NE(at, std::string::npos) << r->message;
  EXPECT_GT(std::stod(r->message.substr(at + 11)), 7.0) << r->message;  // the tip, 8 mm up, within a voxel
  ASSERT_TRUE(r->where);
  EXPECT_NEAR(r->where->x, 14.5, 1.0);
  EXPECT_GT(r->where->z, 10);
}

TEST(Execution, AFilledSlotIsExcessMaterial) {
  Case c(1.0);
  const Solid block = c.box({{5, 5, 0}, {25, 25, 6}});
  c.file.design = subtract(block, c.box({{13, 0, 2}, {17, 30, 10}}));  // a 4 mm slot the plan fills
  const Execution run = execute_plan(c.file, c.plan({c.deposit(block)}), machine());
  ASSERT_TRUE(has(run, "excess_material")) << all_reasons(run);
  EXPECT_GT(run.deviation.over_volume, 0.8 * 4 * 20 * 4);
}

// A pad built on the plate, then a block 6 mm above the plate beside it, over air. A bead
// over air would fall, so the head does not lay it (docs/toolpaths.md): the second action's
// toolpath says so, nothing is laid over air, and the plan is rejected because the part as
// built lacks the block. (The simulator's own alarm for a bead over air, 12
// DEPOSITION_OVER_AIR, is tested with hand-made moves in tests/sim/material_test.cpp.)
TEST(Execution, DepositOverAirIsNotLaidAndThePartLacksIt) {
  Case c(1.0);
  const Solid pad = c.box({{20, 5, 0}, {30, 15, 2}}), floating = c.box({{5, 5, 6}, {15, 15, 9}});
  c.file.design = unite(pad, floating);
  const Execution run = execute_plan(c.file, c.plan({c.deposit(pad), c.deposit(floating)}), machine());
  ASSERT_EQ(run.exported.actions.size(), 2u) << all_reasons(run);
  EXPECT_TRUE(overhang_not_deposited(run.exported.actions[1])) << all_reasons(run);
  EXPECT_FALSE(has(run, "unsupported_deposit")) << all_reasons(run);
  ASSERT_TRUE(has(run, "missing_material")) << all_reasons(run);
  EXPECT_GT(run.deviation.under_volume, 0.8 * 10 * 10 * 3) << "the floating block is missing";
  EXPECT_FALSE(run.proven());
}

// Validation stops after the plan's last addition when the design's core is missing
// there: the removals after it cannot add it, so the part would be wrong whatever they do.
// The reason names that action; run to the end, the deviation finds the same.
TEST(Execution, TheCoreMissingAfterTheLastAdditionStopsTheRunThere) {
  Case c(1.0);
  const Solid pad = c.box({{20, 5, 0}, {30, 15, 2}}), floating = c.box({{5, 5, 6}, {15, 15, 9}});
  c.file.design = unite(pad, floating);
  const plan::PlanFilePlan plan =
      c.plan({c.deposit(pad), c.deposit(floating), c.mill(c.box({{0, 0, 20}, {40, 30, 24}}), 1)});
  ExecutionOptions validating;
  validating.run_until = RunUntil::FirstFailingAction;
  const Execution stopped = execute_plan(c.file, plan, machine(), validating);
  EXPECT_EQ(stopped.stopped_after, 2) << all_reasons(stopped);
  EXPECT_TRUE(stopped.missing_after_last_addition);
  const plan::RejectionReason* r = first_of(stopped, "missing_material");
  ASSERT_NE(r, nullptr) << all_reasons(stopped);
  EXPECT_EQ(r->action, 2);
  EXPECT_NE(r->message.find("the last that adds material"), std::string::npos) << r->message;
  ASSERT_TRUE(r->where.has_value());
  const geometry::Vec3 at = *r->where;
  EXPECT_TRUE(at.x > 5 && at.x < 15 && at.y > 5 && at.y < 15 && at.z > 6 && at.z < 9) << "in the floating block";
  // Its middle, not a corner: where the missing core is, as one point.
  EXPECT_NEAR(at.x, 10, 1.01);
  EXPECT_NEAR(at.y, 10, 1.01);
  EXPECT_NEAR(at.z, 7.5, 1.01);

  const Execution whole = execute_plan(c.file, plan, machine());
  EXPECT_EQ(whole.stopped_after, 0);
  EXPECT_FALSE(whole.missing_after_last_addition);
  EXPECT_TRUE(has(whole, "missing_material")) << all_reasons(whole);

  // The same actions with the block deposited again at the end are not stopped early.
  const plan::PlanFilePlan again = c.plan({0, 1, 2, 1});
  const Execution later = execute_plan(c.file, again, machine(), validating);
  EXPECT_NE(later.stopped_after, 2) << all_reasons(later);
}

// The build plate is where the simulated machine has it: a stock clamped above the
// domain's floor has no plate under its lowest layer, so a block deposited beside it from
// that layer is over air except where the stock's side carries the beads. The toolpath
// does not lay it (it used to take the lowest material present for the plate, lay the
// block, and the simulator let it fall).
TEST(Execution, ADepositBesideAStockAboveTheFloorHasNoPlateUnderIt) {
  Case c(0.5);
  const Solid raw = c.box({{0, 0, 4}, {20, 20, 10}}), block = c.box({{20, 0, 4}, {30, 20, 8}});
  c.file.design = unite(raw, block);
  const Execution run = execute_plan(c.file, c.plan({c.stock(raw), c.deposit(block)}), machine());
  ASSERT_EQ(run.exported.actions.size(), 2u) << all_reasons(run);
  EXPECT_TRUE(overhang_not_deposited(run.exported.actions[1])) << all_reasons(run);
  EXPECT_FALSE(has(run, "unsupported_deposit")) << all_reasons(run);
  EXPECT_TRUE(has(run, "missing_material")) << all_reasons(run);
}

// A plan that starts by depositing has its plate under the first layer, and the plate
// stays there, fixed to the part: after the part was turned over and milled from below,
// a block deposited from above beside the first one, from the same layer, stands on it.
TEST(Execution, ThePlateOfTheFirstDepositIsStillThereAfterAnotherSetup) {
  Case c(0.5);
  const Solid pad = c.box({{5, 5, 4}, {25, 25, 8}}), step = c.box({{15, 0, -5}, {30, 30, 5}});
  const Solid block = c.box({{25, 5, 4}, {35, 25, 7}});
  c.file.design = unite(subtract(pad, step), block);
  const int d = c.deposit(pad), m = c.mill(step, 1, "bottom"), b = c.deposit(block);
  const Execution run = execute_plan(c.file, c.plan({d, m, b}), machine());
  ASSERT_EQ(run.exported.actions.size(), 3u) << all_reasons(run);
  ASSERT_TRUE(run.exported.actions[1].makes_gcode) << "the mill turns the part over: " << all_reasons(run);
  EXPECT_FALSE(has(run, "unsupported_deposit")) << all_reasons(run);
  EXPECT_FALSE(has(run, "missing_material")) << all_reasons(run);
  EXPECT_GT(run.report.deposited, 0.9 * (20 * 20 * 4 + 10 * 20 * 3)) << all_reasons(run);
}

// A deposit under a table-shaped stock: the head cannot reach it from above.
TEST(Execution, ALayerUnderExistingMaterialIsSkippedAndRejected) {
  Case c(0.5);
  const Solid table = unite(c.box({{0, 0, 6}, {30, 20, 10}}),
                            unite(c.box({{0, 0, 0}, {4, 20, 6}}), c.box({{26, 0, 0}, {30, 20, 6}})));
  const Solid under = c.box({{10, 5, 0}, {20, 15, 4}});
  c.file.design = unite(table, under);
  const int s = c.stock(table);
  const Execution run = execute_plan(c.file, c.plan({s, c.deposit(under)}), machine());
  const plan::RejectionReason* r = first_of(run, "layer_skipped");
  ASSERT_NE(r, nullptr) << all_reasons(run);
  EXPECT_EQ(r->action, 2);
  ASSERT_TRUE(r->where);
  EXPECT_NEAR(r->where->x, 15, 2);
  EXPECT_NEAR(r->where->y, 10, 2);
  EXPECT_LT(r->where->z, 4);
}

// The 10 mm cutter cannot enter a 4 mm slot, so the milling leaves it full; the plan then
// refills the slot it believes empty. Planned against the planned state the head comes down
// through the material still there (the deposit keeps a millimetre off the slot's sides, so
// its rasters do not run up to a wall); planned against the material present it has nothing
// to deposit, and the plan is rejected for what the milling could not reach.
TEST(Execution, HeadTravelIsPlannedAgainstTheMaterialTheMillingReallyLeft) {
  Case c(0.5);
  const Solid raw = c.box({{0, 0, 0}, {30, 20, 10}});
  const Solid slot = c.box({{13, 2, 4}, {17, 18, 12}});
  c.file.design = raw;
  const int s = c.stock(raw);
  const int m = c.mill(slot, 1);
  const int d = c.deposit(c.box({{14, 2, 4}, {16, 18, 10}}));

  ExecutionOptions planned;
  planned.planned_against = PlannedAgainst::PlannedState;
  const Execution blind = execute_plan(c.file, c.plan({s, m, d}), machine(), planned);
  const plan::RejectionReason* rapid = first_of(blind, "rapid_into_material");
  ASSERT_NE(rapid, nullptr) << all_reasons(blind);
  EXPECT_EQ(rapid->action, 3);
  EXPECT_GT(rapid->line, 0);
  ASSERT_TRUE(rapid->where);
  EXPECT_NEAR(rapid->where->x, 15, 4);

  const Execution seen = execute_plan(c.file, c.plan({s, m, d}), machine());
  EXPECT_FALSE(has(seen, "rapid_into_material")) << all_reasons(seen);
  EXPECT_TRUE(has(seen, "unreachable")) << all_reasons(seen);
  EXPECT_FALSE(seen.exported.actions[2].makes_gcode) << "the slot is full: nothing to deposit";
}

// A strip deposited at the foot of a 20 mm wall: the 20 mm nozzle runs into the wall.
TEST(Execution, TheNozzleBodyTouchingMaterialIsACollision) {
  Case c(1.0);
  const Solid wall = c.box({{0, 0, 0}, {5, 20, 20}});
  const Solid strip = c.box({{5, 2, 0}, {7, 18, 2}});
  c.file.design = unite(wall, strip);
  const Execution run = execute_plan(c.file, c.plan({c.stock(wall), c.deposit(strip)}), machine());
  const auto k = kinds(run);
  const bool collision = std::any_of(k.begin(), k.end(), [](const std::string& s) {
    return s == "body_collision" || s == "nozzle_collision" || s == "rapid_into_material";
  });
  EXPECT_TRUE(collision) << all_reasons(run);
}

// A step milled from a raw stock (action 2, as the design wants), then a strip deposited at
// the foot of the 25 mm wall the step leaves (action 3): the nozzle runs into the wall, and
// that is located by its line in the whole plan's program, after every line of action 2,
// not by a line counted from its action's start.
TEST(Execution, TheLinesAreThoseOfTheWholePlansProgram) {
  Case c(1.0);
  const Solid raw = c.box({{0, 0, 0}, {30, 20, 25}}), step = c.box({{15, -5, 5}, {35, 25, 30}});
  const Solid strip = c.box({{15, 2, 5}, {17, 18, 7}});
  c.file.design = unite(subtract(raw, step), strip);
  const int s = c.stock(raw);
  const int m = c.mill(step, 1);
  const int d = c.deposit(strip);
  const plan::PlanFilePlan plan = c.plan({s, m, d});
  const Execution run = execute_plan(c.file, plan, machine());
  const gcode::PostedProgram whole = gcode::post_program(run.exported.programs(), machine());
  EXPECT_EQ(run.program.lines, whole.lines);
  const plan::RejectionReason* r = first_of(run, "nozzle_collision");
  if (!r) r = first_of(run, "body_collision");
  ASSERT_NE(r, nullptr) << all_reasons(run);
  EXPECT_EQ(r->action, 3);
  const gcode::ProgramAction* a = whole.action_at(std::uint32_t(r->line));
  ASSERT_NE(a, nullptr) << "line " << r->line;
  EXPECT_EQ(a->number, 3);
  std::uint32_t last_of_step = 0;
  for (const gcode::ProgramAction& pa : whole.actions)
    if (pa.number == 2) last_of_step = pa.last_line;
  ASSERT_GT(last_of_step, 10u) << "action 2 has no lines in the whole program";
  EXPECT_GT(std::uint32_t(r->line), last_of_step);
}

// Two ways to mill a 4 mm wide pocket into a block: with the 10 mm rougher (cheaper per
// mm³, but it cannot enter) and with the 3 mm flat. The search offers the cheaper first,
// validation rejects it, and the next, valid, plan is returned.
TEST(Execution, TheSearchGoesOnToTheNextValidPlan) {
  Case c(1.0);
  const Solid block = c.box({{0, 0, 0}, {30, 20, 10}}), pocket = c.box({{13, 2, 4}, {17, 18, 12}});
  c.file.design = subtract(block, pocket);
  c.stock(block);
  c.mill(pocket, 1);
  c.mill(pocket, 3);
  using planner::testing::VoxelPrimitive;
  const planner::testing::VoxelProblem vp = planner::testing::make_problem(
      {VoxelPrimitive{"P1", config::Mode::Additive, true, 0.0, c.file.primitives[0].region},
       VoxelPrimitive{"P2", config::Mode::Subtractive, false, 0.2, c.file.primitives[1].region},
       VoxelPrimitive{"P3", config::Mode::Subtractive, false, 1.0, c.file.primitives[2].region}},
      c.file.design, c.file.domain, c.file.tolerance);
  std::vector<std::vector<plan::RejectionReason>> rejected;
  planner::SearchOptions options;
  options.top_k = 1;
  options.accept = [&](const planner::Plan& plan) {
    const Execution run = execute_plan(c.file, c.plan([&] {
      std::vector<int> actions;
      for (const planner::PlanStep& s : plan.steps) actions.push_back(s.primitive);
      return actions;
    }()), machine());
    if (!run.proven()) rejected.push_back(run.reasons);
    return run.proven();
  };
  planner::SearchStats stats;
  const std::vector<planner::Plan> plans = planner::find_plans(vp.problem, options, &stats);
  ASSERT_EQ(plans.size(), 1u);
  ASSERT_EQ(plans[0].steps.size(), 2u);
  EXPECT_EQ(plans[0].steps[1].primitive, 2) << "the 3 mm flat";
  EXPECT_EQ(stats.rejected, 1);
  ASSERT_EQ(rejected.size(), 1u);
  const auto& reasons = rejected.front();
  EXPECT_TRUE(std::any_of(reasons.begin(), reasons.end(),
                          [](const plan::RejectionReason& r) { return r.kind == "unreachable" && r.action == 2; }))
      << describe_reasons(reasons);
}

}  // namespace
}  // namespace hybridctl::validation
