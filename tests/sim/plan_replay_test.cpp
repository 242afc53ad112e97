// The exported programs really make the plan: the bundled flanged hub is planned on the
// bundled hybrid machine, each action of a plan is exported to G-code, parsed back by
// our interpreter and run in the material simulation from the planned state before it;
// what it leaves must be the planned state after it, within the bounds documented in
// docs/toolpaths.md ("What a replay may differ by").

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "config/machine_loader.hpp"
#include "gcode/interpreter.hpp"
#include "toolpaths/plan_export.hpp"
#include "geometry/mesh.hpp"
#include "geometry/morphology.hpp"
#include "planner/pipeline/plan_report.hpp"
#include "plan/start_stock.hpp"
#include "sim/replay.hpp"

namespace hybridctl::sim {
namespace {

namespace fs = std::filesystem;
using geometry::Solid;

struct Planned {
  config::Machine machine;
  plan::PlanFile file;
};

// Planned once for all tests, at 0.5 mm, and read back from its directory as
// `hybridctl export` does. Not validated by execution (the planner alone): each action is
// replayed here from its planned state, whatever the actions before it really left. The
// hub's best plans mill a plate from -Z and +Z with the 10 mm rougher; plan 6 finishes the
// top with the 6 mm ball; plan 3 (plate, mill from +Z, deposit from -Z, mill from -Z) is
// the first that also deposits. No plan of a bundled part that mills and deposits builds
// what it plans: the deposit's nozzle body runs into the walls around it (a documented
// limit, docs/toolpaths.md), and validation rejects those plans.
const Planned& planned() {
  static const Planned p = [] {
    Planned out;
    out.machine = config::load_machine(HYBRIDCTL_SOURCE_DIR "/examples/machines/hybrid-3axis.yaml");
    const auto mesh = geometry::read_stl(HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl");
    planner::PlanningOptions options;
    options.voxel_size = 0.5;
    options.top_k = 10;  // plan 9 deposits the hub from -Z and mills it
    const planner::PlanningResult r = planner::plan_part(mesh, "flanged-hub.stl", out.machine, options);
    const fs::path dir = fs::temp_directory_path() / ("hybridctl-replay-" + std::to_string(::getpid()));
    // The STL copied into the directory (design.stl), as `plan` does: milling with flat
    // tools finishes the walls on it (docs/toolpaths.md, "Wall finishing"), which the
    // replays here judge on the voxels.
    planner::write_plan_directory(r, {HYBRIDCTL_SOURCE_DIR "/examples/parts/flanged-hub.stl", "hybrid-3axis.yaml",
                                      out.machine.name, ""},
                                  dir);
    out.file = plan::read_plan_file(dir);
    fs::remove_all(dir);
    return out;
  }();
  return p;
}

// The rank of the first plan that mills with `tool` (0: any tool) and deposits (beyond its
// raw stock) or not as `deposits` says; 0 when there is none.
int first_rank(int tool, bool deposits) {
  const Planned& p = planned();
  for (std::size_t k = 0; k < p.file.plans.size(); ++k) {
    bool mills = false, deposited = false;
    for (const auto& a : p.file.plans[k].actions) {
      const plan::PlanFilePrimitive& prim = p.file.primitives[std::size_t(a.primitive)];
      mills = mills || (prim.mode == config::Mode::Subtractive && (tool == 0 || prim.tool_number == tool));
      deposited = deposited || (prim.mode == config::Mode::Additive && !prim.raw_stock());
    }
    if (mills && deposited == deposits) return int(k) + 1;
  }
  return 0;
}

struct ActionFigures {
  double roi = 0, missing = 0, extra = 0, worst_extra = 0, worst_missing = 0, gouge = 0;
  int rapid_incidents = 0, collisions = 0, errors = 0;
};

// Replays every action of plan `rank` and checks it; returns the figures per action.
std::vector<ActionFigures> replay_plan(int rank) {
  const Planned& p = planned();
  const plan::PlanFilePlan& plan = p.file.plans[std::size_t(rank - 1)];
  const toolpaths::PlanExport exported = toolpaths::export_plan(p.file, plan, p.machine);
  const double h = p.file.lattice.voxel_size;
  std::vector<ActionFigures> out;
  for (const toolpaths::ExportedAction& a : exported.actions) {
    if (!a.makes_gcode) continue;
    const std::string text = gcode::write_action(a.program, p.machine);
    ReplayOptions options;
    options.protected_region =
        plan::spared_by_cuts(p.file, &p.file.primitives.at(std::size_t(plan.actions.at(std::size_t(a.step - 1)).primitive)));
    const ReplayResult r = replay_program(text, p.machine, a.before, options, a.primitive + ".ngc");
    ActionFigures f;
    f.roi = a.roi.volume();
    const Solid missing = subtract(a.after, r.stock), extra = subtract(r.stock, a.after);
    f.missing = missing.volume();
    f.extra = extra.volume();
    f.worst_extra = geometry::farthest_distance(extra, a.after);
    // Outside the domain is air too: measure depth against a box one voxel wider.
    geometry::IndexBox wider = a.after.storage_box();
    wider = {{wider.lo.x - 1, wider.lo.y - 1, wider.lo.z - 1}, {wider.hi.x + 1, wider.hi.y + 1, wider.hi.z + 1}};
    f.worst_missing = geometry::farthest_distance(missing, complement(a.after, wider));
    f.gouge = r.report.gouge;
    for (const Incident& i : r.report.incidents) {
      f.rapid_incidents += i.kind == IncidentKind::RapidIntoMaterial;
      f.collisions += i.kind == IncidentKind::BodyCollision;
    }
    f.errors = int(r.errors.size());
    std::printf("plan %d action %d %s %s: roi %.1f mm3, missing %.1f mm3 (worst %.2f mm), extra %.1f mm3 (worst %.2f mm), "
                "gouge %.1f mm3, %d rapid incidents, %d collisions, %d errors, %d motions\n",
                rank, a.step, a.primitive.c_str(), a.program.additive ? "deposit" : "remove", f.roi, f.missing,
                f.worst_missing, f.extra, f.worst_extra, f.gouge, f.rapid_incidents, f.collisions, f.errors, r.motions);
    for (const Incident& i : r.report.incidents)
      if (i.kind != IncidentKind::UnsupportedDeposition) std::printf("  %s\n", describe(i).c_str());
    for (const std::string& e : r.errors) std::printf("  %s\n", e.c_str());
    // The invariants: nothing of the design beyond the tolerance is cut, no rapid meets
    // material, the holder never touches, and every line is good G-code.
    EXPECT_EQ(f.gouge, 0) << a.primitive;
    EXPECT_EQ(f.rapid_incidents, 0) << a.primitive;
    EXPECT_EQ(f.collisions, 0) << a.primitive;
    EXPECT_EQ(f.errors, 0) << a.primitive;
    // The documented bounds (docs/toolpaths.md, "What a replay may differ by").
    if (a.program.additive) {
      const config::AdditiveHead* head = nullptr;
      for (const auto& hd : p.machine.heads)
        if (a.program.path.instrument == hd.name) head = &hd;
      EXPECT_NE(head, nullptr);
      if (!head) continue;
      EXPECT_LE(f.extra, 0.10 * f.roi) << a.primitive << ": overfill";
      EXPECT_LE(f.worst_extra, head->bead.width / 2 + h) << a.primitive << ": overfill depth";
      // Thin voids between neighbouring tracks and layers (ellipsoid beads).
      EXPECT_LE(f.missing, 0.02 * f.roi) << a.primitive << ": left empty";
    } else {
      EXPECT_EQ(f.missing, 0) << a.primitive << ": the cut took material that must stay";
      EXPECT_LE(f.extra, 0.25 * f.roi) << a.primitive << ": leftover";
      EXPECT_LE(f.worst_extra, 2 * h) << a.primitive << ": leftover depth";
    }
    out.push_back(f);
  }
  return out;
}

TEST(PlanReplay, TheBestPlanOfTheFlangedHubBuildsWhatItPlans) {
  const auto figures = replay_plan(1);
  ASSERT_FALSE(figures.empty());
}

// The 6 mm ball finisher leaves scallops and corners: within the documented bounds.
TEST(PlanReplay, APlanOfTheFlangedHubWithTheBallFinisherBuildsWhatItPlans) {
  const int rank = first_rank(2, false);
  ASSERT_GT(rank, 0) << "no plan of the flanged hub mills with T2";
  const auto figures = replay_plan(rank);
  ASSERT_FALSE(figures.empty());
}

// What the whole program of a hybrid plan does, parsed back: a tool change precedes every
// spindle start, the spindle runs only with a cutting tool, deposition only with a head,
// and never both at once.
TEST(PlanReplay, TheWholeProgramChangesToolsBeforeStartingThem) {
  const Planned& p = planned();
  const int rank = first_rank(0, true);
  ASSERT_GT(rank, 0) << "no plan of the flanged hub mills and deposits";
  const toolpaths::PlanExport exported = toolpaths::export_plan(p.file, p.file.plans[std::size_t(rank - 1)], p.machine);
  const std::string text = gcode::write_program(exported.programs(), p.machine);
  gcode::Interpreter interp(p.machine, "plan.ngc");
  int line = 0, tool = 0, spindle_starts = 0, depositions = 0;
  bool spindle = false, depositing = false;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const gcode::LineResult& r = interp.execute_line(std::string_view(text).substr(start, end - start), ++line);
    start = end == std::string::npos ? text.size() : end + 1;
    for (const gcode::Event& e : r.events) {
      switch (e.kind) {
        case gcode::EventKind::ToolChange:
          EXPECT_FALSE(spindle) << "line " << line << ": tool change with the spindle running";
          EXPECT_FALSE(depositing) << "line " << line << ": tool change while depositing";
          tool = e.tool;
          break;
        case gcode::EventKind::SpindleStart:
          ++spindle_starts;
          EXPECT_NE(p.machine.find_tool(tool), nullptr) << "line " << line << ": spindle started without a cutting tool";
          EXPECT_FALSE(depositing) << "line " << line;
          spindle = true;
          break;
        case gcode::EventKind::SpindleStop: spindle = false; break;
        case gcode::EventKind::DepositionOn:
          ++depositions;
          EXPECT_EQ(p.machine.find_tool(tool), nullptr) << "line " << line << ": deposition with a cutter in the spindle";
          EXPECT_FALSE(spindle) << "line " << line << ": deposition with the spindle running";
          depositing = true;
          break;
        case gcode::EventKind::DepositionOff: depositing = false; break;
        default: break;
      }
    }
  }
  EXPECT_GT(spindle_starts, 0);
  EXPECT_GT(depositions, 0);
  EXPECT_FALSE(spindle);
  EXPECT_FALSE(depositing);
}

}  // namespace
}  // namespace hybridctl::sim
