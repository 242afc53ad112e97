#pragma once
// Validation by execution as a candidate validator (plan::CandidateValidator): every
// candidate plan the search finds is exported and executed (validation/execution.hpp)
// before it is offered; what the run showed goes back to the planner, which rejects the
// candidate on its reasons and learns from the material it left
// (planner/pipeline/candidate_execution.hpp). Knows plan files, not the planner.
//
//   planner::PlanningOptions options;
//   planner::validate_by_execution(options, validation::plan_validator(machine), machine.name);
//   const planner::PlanningResult r = planner::plan_part(mesh, name, machine, options);
//   // r.plans: proven; r.rejected: the candidates that failed, with their reasons

#include <memory>

#include "config/machine.hpp"
#include "plan/candidate_run.hpp"
#include "validation/execution.hpp"

namespace hybridctl::validation {

// The executor, and what it knows without executing: a candidate that begins with the
// actions a rejected one failed in, that repeats a failure against the STL, or (past a few
// such failures and none passing) that has no primitive those did not; and the inside
// corners of a design no cutter of the machine reaches. It keeps `machine`
// by reference (it must outlive planning). Candidates resume from the prefixes `cache`
// holds (one is made when none is given; pass one to read its stats); it must serve this
// executor alone, on one plan file's grid and primitives.
plan::CandidateValidator plan_validator(const config::Machine& machine, ExecutionOptions options = {},
                                       std::shared_ptr<PrefixCache> cache = nullptr);

}  // namespace hybridctl::validation
