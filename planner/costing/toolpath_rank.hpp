#pragma once
// The estimate checked against the toolpaths (docs/costs.md): each action's estimated
// time (its volume at the capability's rate) against the cycle time of the program
// export writes for it (`gcode check`'s time model). Where some action's two differ by
// more than a quarter, the toolpath is the truth: the offered plans are ranked by their
// cost with the toolpaths' times in place of the estimates.

#include <cstddef>
#include <vector>

#include "config/machine.hpp"
#include "planner/primitives/machine_primitives.hpp"
#include "planner/problem/problem.hpp"

namespace hybridctl::planner {

// How far an action's estimate may be from its toolpath's cycle time before the plans are
// ranked by the toolpaths: 25 %.
inline constexpr double kEstimateTolerance = 0.25;

// Whether an action's estimate (minutes of work, changes aside) is off its toolpath's
// cycle time by more than kEstimateTolerance. Actions of under a minute either way do not
// count: a few seconds of lifts and rapids are not a wrong rate.
bool estimate_off(double estimated, double toolpath);

// Minutes of work an action's estimate gives it: its volume at its capability's rate.
double estimated_work(const config::Machine& machine, const std::vector<Primitive>& primitives, const PlanStep& step);

// A plan's cost in the objective with each action's toolpath time in place of its
// estimated work; `toolpath` holds minutes per action. Cost factors are not times: for
// them it is the plan's cost.
double cost_with_toolpaths(const config::Machine& machine, const std::vector<Primitive>& primitives,
                           config::Objective objective, const Plan& plan, const std::vector<double>& toolpath);

// How the plans rank by their toolpaths: `ranked` when some action of some plan has its
// estimate off, every plan's toolpaths are known and the objective is time or money; then
// `order` (stable: plans the toolpaths cost alike keep the search's order) and `costs` (per
// plan, in the search's order). `order` is the search's own otherwise.
struct ToolpathRanking {
  int estimates_off = 0;
  bool ranked = false;
  std::vector<std::size_t> order;
  std::vector<double> costs;
};
ToolpathRanking rank_by_toolpaths(const config::Machine& machine, const std::vector<Primitive>& primitives,
                                  config::Objective objective, const std::vector<Plan>& plans,
                                  const std::vector<std::vector<double>>& toolpath_minutes);

}  // namespace hybridctl::planner
