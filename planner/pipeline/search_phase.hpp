#pragma once
// The search step of plan_part (docs/search.md, docs/validation.md): the plans found by
// rounds of search, each candidate offered to PlanningOptions::validate, the problem
// corrected by what executed candidates showed and searched again; a longer proof on
// another core when the first ran out of budget; then the verdict's outcome.

#include <functional>
#include <string>

#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

// Progress: a phase name and a fraction of it done.
using Progress = std::function<void(const std::string& phase, double fraction)>;

// Fills r.plans, r.rejected, r.learned, r.search and the verdict's summary from the problem,
// the check and the proofs already in `r`; `validation_seconds` counts the time the
// validate hook took.
void search_phase(int top_k, const PlanningOptions& options, const Progress& progress, PlanningResult& r,
                  double& validation_seconds);

// The verdict once the search is over: manufacturable only with plans in hand; without,
// undecided when the search stopped at its limits or ran on primitives corrected by
// execution (a correction is not a proof, docs/validation.md) and nothing decided the part
// before it; not manufacturable otherwise.
void settle_outcome(PlanningResult& r);

}  // namespace hybridctl::planner
