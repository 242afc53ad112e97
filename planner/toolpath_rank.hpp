#pragma once
// The estimate checked against the toolpaths (docs/costs.md): each action's estimated
// time (its volume at the capability's rate) against the cycle time of the program
// export writes for it (`gcode check`'s time model). Where some action's two differ by
// more than a quarter, the toolpath is the truth: the offered plans are ranked by their
// cost with the toolpaths' times in place of the estimates.

#include <vector>

#include "config/machine.hpp"
#include "planner/planning.hpp"

namespace hybridctl::planner {

// How far an action's estimate may be from its toolpath's cycle time before the plans are
// ranked by the toolpaths: 25 %.
inline constexpr double kEstimateTolerance = 0.25;

// Whether an action's estimate (minutes of work, changes aside) is off its toolpath's
// cycle time by more than kEstimateTolerance. Actions of under a minute either way do not
// count: a few seconds of lifts and rapids are not a wrong rate.
bool estimate_off(double estimated, double toolpath);

// A plan's cost in the objective with each action's toolpath time in place of its
// estimated work; `toolpath` holds minutes per action. Cost factors are not times: for
// them it is the plan's cost.
double cost_with_toolpaths(const config::Machine& machine, const PlanningResult& r, const Plan& plan,
                           const std::vector<double>& toolpath);

// Ranks r.plans (with their deviations, estimates and toolpath times) by cost_with_toolpaths
// when some action of some plan has its estimate off and the objective is time or money
// (r.ranked_by_toolpaths); stable, so plans the toolpaths cost alike keep the search's order.
void rank_by_toolpaths(const config::Machine& machine, PlanningResult& r);

// Minutes of work an action's estimate gives it: its volume at its capability's rate.
double estimated_work(const config::Machine& machine, const PlanningResult& r, const PlanStep& step);

}  // namespace hybridctl::planner
