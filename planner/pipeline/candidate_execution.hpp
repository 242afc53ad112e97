#pragma once
// Validation by execution as the planner sees it (PlanningOptions::validate,
// docs/validation.md): each candidate the search finds is handed, as a plan file, to an
// executor (validation::plan_validator runs its G-code on the simulated machine); its
// reasons reject it, and the material it left shows which primitives fell short of the
// model or spilled past it (planner/pipeline/shortfall.hpp), which corrects the search.

#include <string>

#include "plan/candidate_run.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

// One candidate of a planning result as the plan file names it (rank 0).
plan::PlanFilePlan candidate_plan(const PlanningResult& result, const Plan& plan);

// Sets options.validate from `validator.execute`, options.known_failure from
// `validator.known` (candidates it would turn down unexecuted are passed over uncounted),
// options.corners from `validator.corners`,
// and options.toolpath_minutes, cycle_time and exact_deviation to what it gave the plans it
// proved (the times rank the offered plans where the estimate is far off, docs/costs.md).
// The planning result is turned into a plan file (to_plan_file, named `machine_name`)
// once, at the first candidate: the grid, the design and the primitives do not change
// after that.
void validate_by_execution(PlanningOptions& options, plan::CandidateValidator validator, const std::string& machine_name);

// What a run of `plan` showed it fell short on or spilled onto, as validation's hook
// reports it: no shortfalls for a run with no material (nothing ran).
CandidateCheck learn_from_run(const PlanningResult& result, const Plan& plan, const plan::PlanFile& file,
                              plan::CandidateRun run, std::optional<geometry::Solid>& core);

}  // namespace hybridctl::planner
