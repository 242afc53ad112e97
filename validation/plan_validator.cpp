#include "validation/plan_validator.hpp"

#include <algorithm>
#include <memory>
#include <utility>
#include <optional>

#include "common/error.hpp"
#include "gcode/check.hpp"
#include "gcode/post.hpp"
#include "planner/plan_report.hpp"
#include "plan/start_stock.hpp"

namespace hybridctl::validation {

plan::PlanFilePlan candidate_plan(const planner::PlanningResult& r, const planner::Plan& plan) {
  plan::PlanFilePlan out{0, planner::expression(r.problem, plan), plan.cost, {}};
  for (const planner::PlanStep& step : plan.steps) out.actions.push_back({step.primitive, step.volume, step.cost});
  return out;
}

namespace {

// Minutes per action of an execution that ran to its end: each action's own program under
// the time model of `gcode check`.
std::vector<double> action_minutes(const Execution& run, const config::Machine& machine) {
  std::vector<double> minutes;
  for (const toolpaths::ExportedAction& a : run.exported.actions) {
    if (!a.makes_gcode) {
      minutes.push_back(0);
      continue;
    }
    const std::string text = gcode::write_action(a.program, machine);
    minutes.push_back(gcode::check_program(text, machine, a.primitive).time.total / 60.0);
  }
  return minutes;
}

}  // namespace

void use_validation(planner::PlanningOptions& options, const config::Machine& machine) {
  auto times = std::make_shared<ToolpathTimes>();
  options.validate = plan_validator(machine, {}, nullptr, times);
  options.toolpath_minutes = [times](const planner::Plan& plan) {
    std::vector<int> key;
    for (const planner::PlanStep& s : plan.steps) key.push_back(s.primitive);
    const auto it = times->find(key);
    return it == times->end() ? std::vector<double>{} : it->second;
  };
}

PlanCheck plan_validator(const config::Machine& machine, ExecutionOptions options, std::shared_ptr<PrefixCache> cache,
                         std::shared_ptr<ToolpathTimes> times) {
  struct State {
    ExecutionOptions options;
    std::optional<plan::PlanFile> file;  // the planning result's grid, design and primitives
    // Execution is deterministic and an action depends only on the ones before it: a
    // candidate that begins with the actions a rejected one failed in fails the same way;
    // one that failed for the core missing after its last addition, so long as the
    // candidate only removes after them (Execution::missing_after_last_addition).
    struct FailedPrefix {
      std::vector<int> primitives;
      std::vector<plan::RejectionReason> reasons;
      bool only_if_removals_follow = false;
    };
    std::vector<FailedPrefix> failed_prefixes;
    // ... and the same holds for the prefixes that went right: candidates go on from there.
    std::shared_ptr<PrefixCache> cache;
    std::optional<geometry::Solid> core;  // the design's core (plan::spared_by_cuts), once
  };
  // A candidate is rejected at its first failing action: its first reasons are enough.
  options.run_until = RunUntil::FirstFailingAction;
  auto state = std::make_shared<State>();
  state->options = std::move(options);
  state->cache = cache ? std::move(cache) : std::make_shared<PrefixCache>();
  return [&machine, state, times](const planner::PlanningResult& r, const planner::Plan& plan) {
    if (!state->file) {
      // No plans yet: only the grid, the design and the primitives are taken.
      const planner::ReportSources sources{"", "", machine.name, ""};
      state->file = planner::to_plan_file(r, sources, ".");
    }
    const plan::PlanFilePlan candidate = candidate_plan(r, plan);
    const auto removes = [&](const plan::PlanFileAction& a) {
      return state->file->primitives.at(std::size_t(a.primitive)).mode == config::Mode::Subtractive;
    };
    for (const State::FailedPrefix& failed : state->failed_prefixes)
      if (failed.primitives.size() <= candidate.actions.size() &&
          std::equal(failed.primitives.begin(), failed.primitives.end(), candidate.actions.begin(),
                     [](int p, const plan::PlanFileAction& a) { return p == a.primitive; }) &&
          (!failed.only_if_removals_follow ||
           std::all_of(candidate.actions.begin() + std::ptrdiff_t(failed.primitives.size()), candidate.actions.end(), removes)))
        return planner::CandidateCheck{failed.reasons};
    try {
      Execution run = execute_plan(*state->file, candidate, machine, state->options, state->cache.get());
      if (run.stopped_after > 0) {
        std::vector<int> prefix;
        for (int k = 0; k < run.stopped_after; ++k) prefix.push_back(candidate.actions[std::size_t(k)].primitive);
        state->failed_prefixes.push_back({std::move(prefix), run.reasons, run.missing_after_last_addition});
      }
      if (times && run.proven() && run.exported.actions.size() == candidate.actions.size()) {
        std::vector<int> key;
        for (const plan::PlanFileAction& a : candidate.actions) key.push_back(a.primitive);
        (*times)[key] = action_minutes(run, machine);
      }
      if (run.proven()) return planner::CandidateCheck{};
      const std::size_t executed = run.stopped_after > 0 ? std::size_t(run.stopped_after) : plan.steps.size();
      std::vector<planner::Shortfall> shortfalls = planner::find_shortfalls(r.problem, r.atoms, plan, executed, run.as_built);
      if (shortfalls.empty() && run.missing_after_last_addition) {
        if (!state->core) state->core = plan::spared_by_cuts(*state->file);
        shortfalls = planner::find_missing_core_shortfalls(r.problem, r.atoms, plan, executed,
                                                           geometry::subtract(*state->core, run.as_built));
      }
      if (shortfalls.empty())
        shortfalls = planner::find_skipped_layer_shortfalls(r.problem, r.atoms, plan, executed, run.as_built, run.reasons);
      if (shortfalls.empty()) shortfalls = planner::find_spills(r.problem, r.atoms, plan, executed, run.as_built, run.reasons);
      return planner::CandidateCheck{std::move(run.reasons), std::move(shortfalls)};
    } catch (const InputError& e) {
      // The plan cannot be written for this machine (a move beyond its envelope, ...): it
      // makes no part, and the search goes on.
      return planner::CandidateCheck{{{"not_exportable", 0, 0, e.what(), std::nullopt}}};
    }
  };
}

}  // namespace hybridctl::validation
