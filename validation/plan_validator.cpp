#include "validation/plan_validator.hpp"

#include <memory>
#include <optional>

#include "common/error.hpp"
#include "planner/plan_report.hpp"

namespace hybridctl::validation {

planner::PlanFilePlan candidate_plan(const planner::PlanningResult& r, const planner::Plan& plan) {
  planner::PlanFilePlan out{0, planner::expression(r.problem, plan), plan.cost, {}};
  for (const planner::PlanStep& step : plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
  return out;
}

PlanCheck plan_validator(const config::Machine& machine, ExecutionOptions options) {
  struct State {
    ExecutionOptions options;
    std::optional<planner::PlanFile> file;  // the planning result's grid, design and primitives
  };
  // A candidate is rejected at its first failing action: its first reasons are enough.
  options.run_until = RunUntil::FirstFailingAction;
  auto state = std::make_shared<State>(State{std::move(options), std::nullopt});
  return [&machine, state](const planner::PlanningResult& r, const planner::Plan& plan) {
    if (!state->file) {
      // No plans yet: only the grid, the design and the primitives are taken.
      const planner::ReportSources sources{"", "", machine.name, ""};
      state->file = planner::to_plan_file(r, sources, ".");
    }
    try {
      return execute_plan(*state->file, candidate_plan(r, plan), machine, state->options).reasons;
    } catch (const InputError& e) {
      // The plan cannot be written for this machine (a move beyond its envelope, ...): it
      // makes no part, and the search goes on.
      return std::vector<planner::RejectionReason>{{"not_exportable", 0, 0, e.what(), std::nullopt}};
    }
  };
}

}  // namespace hybridctl::validation
