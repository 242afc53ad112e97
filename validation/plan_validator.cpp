#include "validation/plan_validator.hpp"

#include <algorithm>
#include <memory>
#include <utility>
#include <optional>

#include "common/error.hpp"
#include "planner/plan_report.hpp"

namespace hybridctl::validation {

planner::PlanFilePlan candidate_plan(const planner::PlanningResult& r, const planner::Plan& plan) {
  planner::PlanFilePlan out{0, planner::expression(r.problem, plan), plan.cost, {}};
  for (const planner::PlanStep& step : plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
  return out;
}

PlanCheck plan_validator(const config::Machine& machine, ExecutionOptions options, std::shared_ptr<PrefixCache> cache) {
  struct State {
    ExecutionOptions options;
    std::optional<planner::PlanFile> file;  // the planning result's grid, design and primitives
    // Execution is deterministic and an action depends only on the ones before it: a
    // candidate that begins with the actions a rejected one failed in fails the same way.
    std::vector<std::pair<std::vector<int>, std::vector<planner::RejectionReason>>> failed_prefixes;
    // ... and the same holds for the prefixes that went right: candidates go on from there.
    std::shared_ptr<PrefixCache> cache;
  };
  // A candidate is rejected at its first failing action: its first reasons are enough.
  options.run_until = RunUntil::FirstFailingAction;
  auto state = std::make_shared<State>();
  state->options = std::move(options);
  state->cache = cache ? std::move(cache) : std::make_shared<PrefixCache>();
  return [&machine, state](const planner::PlanningResult& r, const planner::Plan& plan) {
    if (!state->file) {
      // No plans yet: only the grid, the design and the primitives are taken.
      const planner::ReportSources sources{"", "", machine.name, ""};
      state->file = planner::to_plan_file(r, sources, ".");
    }
    const planner::PlanFilePlan candidate = candidate_plan(r, plan);
    for (const auto& [prefix, reasons] : state->failed_prefixes)
      if (prefix.size() <= candidate.actions.size() &&
          std::equal(prefix.begin(), prefix.end(), candidate.actions.begin(),
                     [](int p, const planner::PlanFileAction& a) { return p == a.primitive; }))
        return reasons;
    try {
      Execution run = execute_plan(*state->file, candidate, machine, state->options, state->cache.get());
      if (run.stopped_after > 0) {
        std::vector<int> prefix;
        for (int k = 0; k < run.stopped_after; ++k) prefix.push_back(candidate.actions[std::size_t(k)].primitive);
        state->failed_prefixes.emplace_back(std::move(prefix), run.reasons);
      }
      return std::move(run.reasons);
    } catch (const InputError& e) {
      // The plan cannot be written for this machine (a move beyond its envelope, ...): it
      // makes no part, and the search goes on.
      return std::vector<planner::RejectionReason>{{"not_exportable", 0, 0, e.what(), std::nullopt}};
    }
  };
}

}  // namespace hybridctl::validation
