#pragma once
// Validation by execution as the planner's hook (PlanningOptions::validate): every
// candidate plan the search finds is exported and executed (validation/execution.hpp)
// before it is offered; its reasons, if any, reject it and the search goes on, and what
// its execution left short of the plan's atoms (planner/shortfall.hpp) corrects the search.
//
//   planner::PlanningOptions options;
//   options.validate = validation::plan_validator(machine);
//   const planner::PlanningResult r = planner::plan_part(mesh, name, machine, options);
//   // r.plans: proven; r.rejected: the candidates that failed, with their reasons

#include <functional>
#include <map>
#include <memory>
#include <vector>

#include "config/machine.hpp"
#include "planner/planning.hpp"
#include "validation/execution.hpp"

namespace hybridctl::validation {

using PlanCheck = std::function<planner::CandidateCheck(const planner::PlanningResult&, const planner::Plan&)>;

// Per proven candidate (its primitives in order), each action's cycle time in minutes as
// `gcode check` estimates it from the action's own program (0 for one that makes no G-code).
using ToolpathTimes = std::map<std::vector<int>, std::vector<double>>;

// The hook. It keeps `machine` by reference (it must outlive planning) and turns the
// planning result into a plan file (planner::to_plan_file) once, at the first candidate.
// Candidates resume from the prefixes `cache` holds (one is made when none is given; pass
// one to read its stats); it must serve this validator alone.
PlanCheck plan_validator(const config::Machine& machine, ExecutionOptions options = {},
                         std::shared_ptr<PrefixCache> cache = nullptr, std::shared_ptr<ToolpathTimes> times = nullptr);

// Validation by execution for `plan_part`: the hook, and the toolpaths' cycle times of the
// plans it proved (PlanningOptions::toolpath_minutes), which rank the offered plans where
// the estimate is far off (docs/costs.md).
void use_validation(planner::PlanningOptions& options, const config::Machine& machine);

// One candidate of a planning result as the plan file names it (rank 0).
plan::PlanFilePlan candidate_plan(const planner::PlanningResult& result, const planner::Plan& plan);

}  // namespace hybridctl::validation
