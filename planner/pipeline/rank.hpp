#pragma once
// The offered plans ranked by their toolpaths (planner/costing/toolpath_rank.hpp) in a
// planning result: the last step of plan_part.

#include <vector>

#include "config/machine.hpp"
#include "planner/pipeline/planning.hpp"

namespace hybridctl::planner {

// Ranks r.plans (with their deviations, estimates and toolpath times) by their cost with
// the toolpaths' times where some action's estimate is off (r.ranked_by_toolpaths,
// r.toolpath_costs); r.search_rank keeps each plan's place in the search's order.
void rank_by_toolpaths(const config::Machine& machine, PlanningResult& r);

// cost_with_toolpaths for a plan of a planning result.
double cost_with_toolpaths(const config::Machine& machine, const PlanningResult& r, const Plan& plan,
                           const std::vector<double>& toolpath);

}  // namespace hybridctl::planner
