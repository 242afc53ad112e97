#include "validation/execution.hpp"

#include <optional>

#include "common/error.hpp"
#include "gcode/post.hpp"
#include "planner/start_stock.hpp"
#include "sim/executor.hpp"

namespace hybridctl::validation {
namespace {

using geometry::Solid;

// `s` on the plan's lattice with the plan's domain as its storage: the simulated world is
// the domain planning looked at, so deposit beyond the raw stock's box is not lost.
Solid on_domain(const Solid& s, const planner::PlanFile& file) {
  Solid out(file.lattice, file.domain);
  s.for_each_voxel([&](geometry::Index3 v) {
    if (file.domain.contains(v)) out.set(v);
  });
  return out;
}

// The whole plan's program fed to the simulated machine action by action. After each
// action the program of the actions made so far is posted and its lines up to the end of
// the newest action's block are executed: the post-processor writes an action's block from
// it and the one before only, so these are the lines of the final program, and incidents
// carry its line numbers.
class IncrementalRun {
 public:
  IncrementalRun(const config::Machine& machine, const planner::PlanFile& file, const planner::PlanFilePlan& plan,
                 Solid start, const ExecutionOptions& options)
      : machine_(machine),
        file_(file),
        plan_(plan),
        options_(options),
        executor_(machine, "plan", executor_options(file, start, options)) {}

  // Programs made without feedback: executed at finish().
  void take(std::vector<gcode::ActionProgram> programs) { made_ = std::move(programs); }

  // The material present after `made`, its program executed. With
  // RunUntil::FirstFailingAction, throws Stopped after an action that went wrong.
  Solid after(const toolpaths::ExportedAction& made) {
    toolpaths::ExportedAction light;  // what the reasons need, without the solids
    light.step = made.step;
    light.primitive = made.primitive;
    light.makes_gcode = made.makes_gcode;
    light.note = made.note;
    light.program = made.program;
    actions_.push_back(std::move(light));
    if (made.makes_gcode) {
      made_.push_back(made.program);
      prefix_ = gcode::post_program(made_, machine_, options_.export_options.post);
      feed(prefix_, prefix_.actions.back().last_line);
    }
    if (options_.run_until == RunUntil::FirstFailingAction &&
        (!made.program.path.defects.empty() || !errors_.empty() || !executor_.report().incidents.empty()))
      throw Stopped{made.step};
    return on_domain(executor_.stock(), file_);
  }

  // Thrown by after() to stop at the first action that went wrong.
  struct Stopped {
    int action = 0;
  };

  // Stopped early: what ran so far.
  void stopped(Execution& out) {
    out.exported.actions = std::move(actions_);
    out.program = std::move(prefix_);
    out.report = executor_.report();
    out.as_built = on_domain(executor_.stock(), file_);
    out.errors = std::move(errors_);
  }

  // The final program, every line of it executed.
  gcode::PostedProgram finish(Execution& out) {
    // A plan with no G-code (the raw stock alone) runs no program.
    gcode::PostedProgram program;
    if (!made_.empty()) program = gcode::post_program(made_, machine_, options_.export_options.post);
    feed(program, program.lines.size());
    out.report = executor_.report();
    out.as_built = on_domain(executor_.stock(), file_);
    out.errors = std::move(errors_);
    return program;
  }

 private:
  static sim::ExecutorOptions executor_options(const planner::PlanFile& file, Solid start,
                                               const ExecutionOptions& options) {
    sim::ExecutorOptions o;
    o.stock = std::move(start);
    o.protected_region = planner::spared_by_cuts(file);  // the header's lines, before any action
    o.simulation = options.simulation;
    return o;
  }
  void feed(const gcode::PostedProgram& program, std::size_t up_to) {
    for (; fed_ < up_to && fed_ < program.lines.size(); ++fed_) {
      protect_for(program.action_at(std::uint32_t(fed_ + 1)));
      const sim::LineOutcome o = executor_.execute_line(program.lines[fed_], int(fed_ + 1));
      if (o.stop != sim::Stop::None && o.stop != sim::Stop::RapidIntoMaterial) errors_.push_back(o.message);
    }
  }

  // Each action's lines spare what that action keeps of the design, not the whole design:
  // a removal may cut design material a later deposit builds again (planner/start_stock.hpp).
  void protect_for(const gcode::ProgramAction* action) {
    if (!action || action->number == protecting_) return;
    protecting_ = action->number;
    const planner::PlanFilePrimitive& p =
        file_.primitives.at(std::size_t(plan_.actions.at(std::size_t(action->number - 1)).primitive));
    executor_.set_protected_region(planner::spared_by_cuts(file_, &p));
  }

  const config::Machine& machine_;
  const planner::PlanFile& file_;
  const planner::PlanFilePlan& plan_;
  const ExecutionOptions& options_;
  sim::ProgramExecutor executor_;
  std::vector<gcode::ActionProgram> made_;
  std::vector<toolpaths::ExportedAction> actions_;
  gcode::PostedProgram prefix_;
  std::size_t fed_ = 0;
  int protecting_ = 0;  // the action whose spared region the executor holds (0: none yet)
  std::vector<std::string> errors_;
};

}  // namespace

Execution execute_plan(const planner::PlanFile& file, const planner::PlanFilePlan& plan, const config::Machine& machine,
                       const ExecutionOptions& options) {
  Execution out;
  IncrementalRun run(machine, file, plan, planner::start_stock(file, plan, machine), options);
  if (options.planned_against == PlannedAgainst::MaterialPresent) {
    try {
      out.exported = toolpaths::export_plan(file, plan, machine, options.export_options,
                                            [&run](const toolpaths::ExportedAction& made) { return run.after(made); });
    } catch (const IncrementalRun::Stopped& stop) {
      run.stopped(out);
      out.stopped_after = stop.action;
      out.reasons = rejection_reasons(out, file, machine);
      return out;
    }
  } else {
    out.exported = toolpaths::export_plan(file, plan, machine, options.export_options);
    run.take(out.exported.programs());
  }
  out.program = run.finish(out);
  out.deviation = planner::measure_deviation(out.as_built, file.design, file.domain, file.tolerance);
  out.reasons = rejection_reasons(out, file, machine);
  return out;
}

}  // namespace hybridctl::validation
